//! Checkpoints of a bed run: everything needed to continue bit for bit,
//! in one binary file written atomically (temporary file, flush, rename).
//!
//! Layout (little endian): the 16-byte magic `GRANBED-CKPT\0\0\0\0`, the
//! format version (u32), the payload length (u64), the FNV-1a 64 checksum
//! of the payload (u64), then the payload: the scene TOML, the run's
//! progress ([`Progress`]) and the assembly state. Floats are stored as
//! their bits, so nothing is rounded.

use std::io::{Seek as _, Write as _};
use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};
use granbed_kernel::Real;
use granbed_kernel::contact::broad::{Bound, GranulePair};
use granbed_kernel::contact::pair::{Constraint, Side};

use super::run::{BedSample, Unloading, Window, set_mean_strains, set_mean_strains_after};
use crate::assembly::die::DieScene;
use crate::assembly::{AssemblyState, Energies, GranuleState, PhaseTimes};

/// File name of the checkpoint in the output directory.
pub const FILE_NAME: &str = "checkpoint.bin";
/// File name of the checkpoint of a withdrawal in progress, beside
/// [`FILE_NAME`] (which keeps the loading's end): written as the withdrawal
/// goes and when an interrupt stops it, removed once it is done.
pub const WITHDRAWAL_FILE_NAME: &str = "withdrawal.bin";
/// Format version written and read.
///
/// 2: samples gained the smallest Gauss-point Jacobian, the largest nodal
/// speed and the penetration, the averaging window the largest nodal speed,
/// the run header the compression's wall time so far (version 1 files are
/// refused).
///
/// 3: each granule gained a flags word (bit 0: still a rigid body). Version
/// 2 files are read with every granule deformable, which continues them
/// with the same motion up to round-off (not bit for bit).
///
/// 4: the energies are followed by the undeformed granule's stable step
/// (f64, the time-step floor's reference), and each granule gained, after
/// its flags, the factor variable mass scaling put on its masses (f64).
/// Version 2 and 3 files are read with factor 1, which they were written
/// with (bit for bit), and the resuming run's own undeformed step.
///
/// 5: samples gained the kinetic energy relative to the imposed
/// compression (after the smallest Gauss-point Jacobian). Older files read
/// it as NaN (not recorded), which the certificate's diagnostic skips.
///
/// 6: the pairs are followed, per pair, by the constraints it holds from
/// the last contact search (a flag u64, 1: held, then the constraints as
/// 11 floats each: `CONSTRAINT_FLOATS`), which the steps up to the next
/// search re-measure (`contact_search_interval` > 1). Older files hold
/// nothing: their first step searches every pair, as it did when written.
///
/// 7: the payload ends with the run's phase times and contact counters so
/// far (3 floats: predict, contact, correct seconds; then 6 counts:
/// sweeps, rigid granule-steps, steps, face-list builds, anchor renewals,
/// pair searches) and the step they count from (u64, 0: the whole run), so
/// the summary's cost figures of a resumed run cover all of it. Older
/// files carry none: the resumed run's figures count from the checkpoint's
/// step, and the summary says so.
///
/// 8: a held constraint's first float may also be 2 or 3: a watch
/// (`Constraint::watch`) on side A or B. Older builds wrote none; the
/// reader takes the values in any version (the layout is that of 7).
///
/// 9: before the phase times, the die wall's normal impulse of the window
/// in progress (f64), then each sample's die-wall normal force (one f64
/// per sample, in order; no length: it is the samples'). Older files read
/// both as NaN (not recorded), the window's as 0 when it is empty.
///
/// 10: the payload ends with the upper punch's withdrawal after the final
/// strain (scene `unload`): a flag (u64, 0: none), then with 1 its rows
/// (as the samples, then each one's die-wall normal force, one f64 per
/// row), its lift-off strain (f64, NaN: none) and its wall time (f64).
/// Older files hold none: a finished run resumed with `unload` runs it.
///
/// 11: the payload ends with a withdrawal in progress (the file
/// [`WITHDRAWAL_FILE_NAME`], whose state is the assembly's in the middle of
/// the withdrawal): a flag (u64, 0: none), then with 1 the loading's last
/// step (u64), the strain of the next row (f64), the wall time so far
/// (f64), the open window (as the loading's, with its die-wall impulse
/// after it) and the rows so far (as the samples, then each one's die-wall
/// normal force). Older files hold none.
pub const VERSION: u32 = 11;
/// The oldest version read.
const OLDEST_VERSION: u32 = 2;
/// Floats per held constraint: side (0: A, 1: B; plus 2 for a watch),
/// slave node, master quad, the four weights, the normal, the gap.
const CONSTRAINT_FLOATS: usize = 11;
/// Granule flag: still a rigid body.
const FLAG_RIGID: u64 = 1;
const MAGIC: &[u8; 16] = b"GRANBED-CKPT\0\0\0\0";
/// Bytes before the payload: the magic, the version, the length, the checksum.
const HEAD_BYTES: usize = 36;
/// Where the header's payload length starts (the checksum follows it).
const LENGTH_AT: u64 = 20;

/// A bed run's progress besides the assembly state.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// The scene as run (TOML).
    pub scene_toml: String,
    /// The die and the bed height.
    pub die: DieScene,
    /// Wall time of the pour, s.
    pub pour_wall_time_s: f64,
    /// Wall time of the compression up to this checkpoint (all segments
    /// of a resumed run), s.
    pub compression_wall_time_s: f64,
    /// Samples written so far.
    pub samples: Vec<BedSample>,
    /// The open averaging window.
    pub window: Window,
    /// Strain of the next output row.
    pub next_output: Real,
    /// Snapshot strains already written (of the sorted list).
    pub snapshots_done: usize,
    /// Phase times and contact counters of the steps from
    /// `counters_from_step` to this checkpoint (format 7; older files:
    /// zero).
    pub counters: PhaseTimes,
    /// The step the counters count from: 0 unless the run went through a
    /// checkpoint older than format 7 (then that checkpoint's step).
    pub counters_from_step: u64,
    /// The withdrawal of a finished run (format 10; the state is still
    /// that of the loading's end).
    pub unloading: Option<Unloading>,
    /// A withdrawal in progress (format 11; only in
    /// [`WITHDRAWAL_FILE_NAME`], whose state is the withdrawal's).
    pub withdrawal: Option<WithdrawalProgress>,
}

/// How far a withdrawal has gone: what it needs, besides the assembly's
/// state and the loading's rows, to go on bit for bit.
#[derive(Clone, Debug, PartialEq)]
pub struct WithdrawalProgress {
    /// The step the loading ended at, where the withdrawal turned.
    pub turn_steps: u64,
    /// Rows so far (their mean strains continue from the loading's).
    pub rows: Vec<BedSample>,
    /// The open averaging window.
    pub window: Window,
    /// Strain of the next row.
    pub next_row: Real,
    /// Wall time of the withdrawal so far, s.
    pub wall_time_s: f64,
}

/// A checkpoint: progress and assembly state.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// The run's progress.
    pub progress: Progress,
    /// The assembly.
    pub state: AssemblyState,
}

/// Whether the rows `a` and `b` hold the same numbers to the bit, NaN
/// included (the mean strains are derived from the rest).
pub fn same_rows(a: &[BedSample], b: &[BedSample]) -> bool {
    let bits = |s: &BedSample| {
        let mut v = sample_to(s).map(f64::to_bits).to_vec();
        v.push(s.die_normal_force_n.to_bits());
        v
    };
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| bits(x) == bits(y))
}

/// A window's floats but its die-wall impulse, in the file's order.
fn window_to(w: &Window) -> [f64; WINDOW_FLOATS] {
    [
        w.time,
        w.impulse[0],
        w.impulse[1],
        w.impulse[2],
        w.pairs,
        w.walls,
        w.min_j,
        w.max_speed,
    ]
}

/// [`window_to`]'s inverse, with the die-wall impulse `die_normal`.
fn window_from(w: [f64; WINDOW_FLOATS], die_normal: f64) -> Window {
    Window {
        time: w[0],
        impulse: [w[1], w[2], w[3]],
        die_normal,
        pairs: w[4],
        walls: w[5],
        min_j: w[6],
        max_speed: w[7],
    }
}

/// FNV-1a, 64 bits.
fn fnv1a(bytes: &[u8]) -> u64 {
    fnv1a_on(FNV1A_START, bytes)
}

/// FNV-1a 64's hash before any byte.
const FNV1A_START: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a 64 of `bytes` continued from the hash `h` of the bytes before.
fn fnv1a_on(h: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(h, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn constraint_to(c: &Constraint) -> [f64; CONSTRAINT_FLOATS] {
    let side = match c.side {
        Side::A => 0.0,
        Side::B => 1.0,
    } + if c.watch { 2.0 } else { 0.0 };
    let [w0, w1, w2, w3] = c.weights;
    let [n0, n1, n2] = c.normal;
    [
        side,
        f64::from(c.slave),
        f64::from(c.quad),
        w0,
        w1,
        w2,
        w3,
        n0,
        n1,
        n2,
        c.gap,
    ]
}

fn constraint_from(v: [f64; CONSTRAINT_FLOATS]) -> anyhow::Result<Constraint> {
    let (side, watch) = match v[0] {
        0.0 => (Side::A, false),
        1.0 => (Side::B, false),
        2.0 => (Side::A, true),
        3.0 => (Side::B, true),
        other => bail!("held constraint on side {other}"),
    };
    // Ids were written from u32s: anything else is a damaged file.
    let id = |x: f64, what: &str| -> anyhow::Result<u32> {
        if x.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&x) {
            Ok(x as u32)
        } else {
            bail!("held constraint with {what} id {x}")
        }
    };
    Ok(Constraint {
        side,
        slave: id(v[1], "slave")?,
        quad: id(v[2], "quad")?,
        weights: [v[3], v[4], v[5], v[6]],
        normal: [v[7], v[8], v[9]],
        gap: v[10],
        watch,
    })
}

/// The payload's encoder: streams its bytes to `out` in blocks of
/// [`Enc::BLOCK`], keeping their length and FNV-1a 64 checksum, so that a
/// checkpoint is written without a copy of the whole payload in memory (for
/// the published scene about 170 MB, on top of the state it encodes). The
/// first write error is kept and every later write skipped.
struct Enc<'w> {
    block: Vec<u8>,
    out: &'w mut dyn std::io::Write,
    len: u64,
    sum: u64,
    error: Option<std::io::Error>,
}

impl<'w> Enc<'w> {
    /// Bytes gathered before they are hashed and written.
    const BLOCK: usize = 1 << 20;

    fn new(out: &'w mut dyn std::io::Write) -> Self {
        Self {
            block: Vec::with_capacity(Self::BLOCK),
            out,
            len: 0,
            sum: FNV1A_START,
            error: None,
        }
    }

    fn put(&mut self, b: &[u8]) {
        self.block.extend_from_slice(b);
        if self.block.len() >= Self::BLOCK {
            self.spill();
        }
    }

    /// Hashes, counts and writes the gathered bytes.
    fn spill(&mut self) {
        self.sum = fnv1a_on(self.sum, &self.block);
        self.len += self.block.len() as u64;
        if self.error.is_none()
            && let Err(e) = self.out.write_all(&self.block)
        {
            self.error = Some(e);
        }
        self.block.clear();
    }

    /// The payload's length and checksum once every byte is written, or the
    /// first write error.
    fn finish(mut self) -> std::io::Result<(u64, u64)> {
        self.spill();
        match self.error {
            Some(e) => Err(e),
            None => Ok((self.len, self.sum)),
        }
    }

    fn u64(&mut self, v: u64) {
        self.put(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        for x in v {
            self.f64(*x);
        }
    }
    fn vecs<const N: usize>(&mut self, v: &[[f64; N]]) {
        self.u64(v.len() as u64);
        for x in v {
            for c in x {
                self.f64(*c);
            }
        }
    }
    fn bytes(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.put(b);
    }
    /// A withdrawal's rows: as the samples, then each one's die-wall
    /// normal force.
    fn rows(&mut self, rows: &[BedSample]) {
        self.vecs(&rows.iter().map(sample_to).collect::<Vec<_>>());
        for row in rows {
            self.f64(row.die_normal_force_n);
        }
    }
}

struct Dec<'a>(&'a [u8]);

impl Dec<'_> {
    fn u64(&mut self) -> anyhow::Result<u64> {
        let Some((head, rest)) = self.0.split_first_chunk::<8>() else {
            bail!("checkpoint payload ends early");
        };
        self.0 = rest;
        Ok(u64::from_le_bytes(*head))
    }
    fn f64(&mut self) -> anyhow::Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn len(&mut self, item_bytes: usize) -> anyhow::Result<usize> {
        let n = self.u64()?;
        match usize::try_from(n) {
            Ok(n) if n.checked_mul(item_bytes).is_some_and(|b| b <= self.0.len()) => Ok(n),
            _ => bail!("checkpoint holds an impossible length {n}"),
        }
    }
    fn f64s(&mut self) -> anyhow::Result<Vec<f64>> {
        let n = self.len(8)?;
        (0..n).map(|_| self.f64()).collect()
    }
    fn vecs<const N: usize>(&mut self) -> anyhow::Result<Vec<[f64; N]>> {
        let n = self.len(8 * N)?;
        (0..n)
            .map(|_| {
                let mut x = [0.0; N];
                for c in &mut x {
                    *c = self.f64()?;
                }
                Ok(x)
            })
            .collect()
    }
    fn bytes(&mut self) -> anyhow::Result<&[u8]> {
        let n = self.len(1)?;
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }
    /// [`Enc::rows`]' rows, their mean strains continuing from the
    /// loading's last row `after`.
    fn rows_after(&mut self, after: Option<&BedSample>) -> anyhow::Result<Vec<BedSample>> {
        let mut rows: Vec<BedSample> = self
            .vecs::<SAMPLE_FLOATS>()?
            .into_iter()
            .map(sample_from)
            .collect();
        for row in &mut rows {
            row.die_normal_force_n = self.f64()?;
        }
        set_mean_strains_after(after, &mut rows);
        Ok(rows)
    }
}

fn energies_to(e: &Energies) -> [f64; 10] {
    [
        e.internal_work,
        e.contact_work,
        e.punch_work,
        e.damping,
        e.gravity_work,
        e.kinetic,
        e.supplied_kinetic,
        e.plastic,
        e.hourglass,
        e.elastic,
    ]
}

fn energies_from(v: [f64; 10]) -> Energies {
    Energies {
        internal_work: v[0],
        contact_work: v[1],
        punch_work: v[2],
        damping: v[3],
        gravity_work: v[4],
        kinetic: v[5],
        supplied_kinetic: v[6],
        plastic: v[7],
        hourglass: v[8],
        elastic: v[9],
    }
}

/// Floats per sample: 19 fields, then the 10 energies. The mean strain is
/// not among them: it is derived from the rows' strains and steps
/// ([`set_mean_strains`]), the same in every version.
const SAMPLE_FLOATS: usize = 29;
/// Floats per sample before version 5 (without the relative kinetic
/// energy, the last of the fields).
const SAMPLE_FLOATS_V4: usize = 28;
/// Floats of the averaging window.
const WINDOW_FLOATS: usize = 8;

fn sample_to(s: &BedSample) -> [f64; SAMPLE_FLOATS] {
    let e = energies_to(&s.energies);
    let head: [f64; SAMPLE_FLOATS - 10] = [
        s.time_s,
        s.strain,
        s.upper_force_n,
        s.lower_force_n,
        s.die_friction_z_n,
        s.upper_pressure_pa,
        s.lower_pressure_pa,
        s.coordination,
        s.coordination_with_walls,
        s.relative_density_mean,
        s.relative_density_solid,
        s.heywood_dv,
        s.heywood_d,
        s.min_jacobian,
        f64::from_bits(s.steps),
        s.max_node_speed_m_s,
        s.penetration_m,
        s.min_gauss_jacobian,
        s.kinetic_relative_j,
    ];
    core::array::from_fn(|i| {
        if i < head.len() {
            head[i]
        } else {
            e[i - head.len()]
        }
    })
}

fn sample_from(v: [f64; SAMPLE_FLOATS]) -> BedSample {
    BedSample {
        time_s: v[0],
        strain: v[1],
        // Derived, not stored: set for all rows by `set_mean_strains`.
        mean_strain: Real::NAN,
        upper_force_n: v[2],
        lower_force_n: v[3],
        die_friction_z_n: v[4],
        // Stored after the held constraints (version 9 on), set there.
        die_normal_force_n: Real::NAN,
        upper_pressure_pa: v[5],
        lower_pressure_pa: v[6],
        coordination: v[7],
        coordination_with_walls: v[8],
        relative_density_mean: v[9],
        relative_density_solid: v[10],
        heywood_dv: v[11],
        heywood_d: v[12],
        min_jacobian: v[13],
        steps: v[14].to_bits(),
        max_node_speed_m_s: v[15],
        penetration_m: v[16],
        min_gauss_jacobian: v[17],
        kinetic_relative_j: v[18],
        energies: energies_from(core::array::from_fn(|i| v[SAMPLE_FLOATS - 10 + i])),
    }
}

impl Checkpoint {
    /// Encodes the payload into `e`.
    fn encode(&self, e: &mut Enc<'_>) {
        let (p, s) = (&self.progress, &self.state);
        e.bytes(p.scene_toml.as_bytes());
        e.f64s(&[
            p.die.die_radius_m,
            p.die.bed_height_m,
            p.die.punch_speed_m_s,
            p.pour_wall_time_s,
            p.next_output,
            p.compression_wall_time_s,
        ]);
        e.u64(p.snapshots_done as u64);
        let w = &p.window;
        e.f64s(&window_to(w));
        e.vecs(&p.samples.iter().map(sample_to).collect::<Vec<_>>());
        e.f64s(&[s.time, f64::from_bits(s.steps), s.dt[0], s.dt[1]]);
        e.f64s(&energies_to(&s.energies));
        e.f64(s.undeformed_step);
        e.u64(s.granules.len() as u64);
        for g in &s.granules {
            e.vecs(&g.x);
            e.vecs(&g.v);
            e.vecs(&g.cp_inv);
            e.vecs(&g.mode);
            let (since, dt, length) = g.time_step;
            e.u64(u64::from(since));
            e.f64(dt);
            e.f64(length);
            e.u64(if g.rigid { FLAG_RIGID } else { 0 });
            e.f64(g.mass_factor);
        }
        e.u64(s.pairs.len() as u64);
        for pair in &s.pairs {
            e.u64(u64::from(pair.a) << 32 | u64::from(pair.b));
        }
        e.vecs(
            &s.built
                .iter()
                .map(|b| [b.centre[0], b.centre[1], b.centre[2], b.radius])
                .collect::<Vec<_>>(),
        );
        for held in (0..s.pairs.len()).map(|k| s.held.get(k)) {
            match held {
                Some(Some(list)) => {
                    e.u64(1);
                    e.vecs(&list.iter().map(constraint_to).collect::<Vec<_>>());
                }
                _ => e.u64(0),
            }
        }
        e.f64(w.die_normal);
        for sample in &p.samples {
            e.f64(sample.die_normal_force_n);
        }
        let c = &p.counters;
        e.f64s(&[c.predict_s, c.contact_s, c.correct_s]);
        for n in [
            c.sweeps,
            c.rigid_granule_steps,
            c.steps,
            c.list_builds,
            c.anchor_renewals,
            c.pair_searches,
            p.counters_from_step,
        ] {
            e.u64(n);
        }
        match &p.unloading {
            None => e.u64(0),
            Some(u) => {
                e.u64(1);
                e.rows(&u.samples);
                e.f64(u.lift_off_strain);
                e.f64(u.wall_time_s);
            }
        }
        match &p.withdrawal {
            None => e.u64(0),
            Some(w) => {
                e.u64(1);
                e.u64(w.turn_steps);
                e.f64(w.next_row);
                e.f64(w.wall_time_s);
                e.f64s(&window_to(&w.window));
                e.f64(w.window.die_normal);
                e.rows(&w.rows);
            }
        }
    }

    fn from_payload(bytes: &[u8], version: u32) -> anyhow::Result<Self> {
        let mut d = Dec(bytes);
        let scene_toml = String::from_utf8(d.bytes()?.to_vec()).context("scene text")?;
        let head = d.f64s()?;
        let [
            die_radius_m,
            bed_height_m,
            punch_speed_m_s,
            pour_wall_time_s,
            next_output,
            compression_wall_time_s,
        ] = <[f64; 6]>::try_from(head).map_err(|_| anyhow::anyhow!("bad run header"))?;
        let snapshots_done = d.u64()? as usize;
        let w = <[f64; WINDOW_FLOATS]>::try_from(d.f64s()?)
            .map_err(|_| anyhow::anyhow!("bad window"))?;
        let mut samples: Vec<BedSample> = match version {
            2..=4 => d
                .vecs::<SAMPLE_FLOATS_V4>()?
                .into_iter()
                .map(|v| {
                    // The relative kinetic energy, not recorded, goes in
                    // as NaN before the energies.
                    let fields = SAMPLE_FLOATS_V4 - 10;
                    sample_from(core::array::from_fn(|i| match i {
                        i if i < fields => v[i],
                        i if i == fields => f64::NAN,
                        i => v[i - 1],
                    }))
                })
                .collect(),
            _ => d
                .vecs::<SAMPLE_FLOATS>()?
                .into_iter()
                .map(sample_from)
                .collect(),
        };
        set_mean_strains(&mut samples);
        let t = <[f64; 4]>::try_from(d.f64s()?).map_err(|_| anyhow::anyhow!("bad time"))?;
        let energies = energies_from(
            <[f64; 10]>::try_from(d.f64s()?).map_err(|_| anyhow::anyhow!("bad energies"))?,
        );
        let undeformed_step = match version {
            2 | 3 => 0.0,
            _ => d.f64()?,
        };
        let n = d.len(24)?;
        let granules = (0..n)
            .map(|_| {
                Ok(GranuleState {
                    x: d.vecs()?,
                    v: d.vecs()?,
                    cp_inv: d.vecs()?,
                    mode: d.vecs()?,
                    time_step: (
                        u32::try_from(d.u64()?).context("time-step memory")?,
                        d.f64()?,
                        d.f64()?,
                    ),
                    rigid: match version {
                        OLDEST_VERSION => false,
                        _ => match d.u64()? {
                            0 => false,
                            FLAG_RIGID => true,
                            other => bail!("unknown granule flags {other:#x}"),
                        },
                    },
                    mass_factor: match version {
                        2 | 3 => 1.0,
                        _ => d.f64()?,
                    },
                })
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        // The element loop tests only det C_p⁻¹ (the kernel's own states
        // are positive definite); a state read from a file is tested in
        // full once.
        for (g, granule) in granules.iter().enumerate() {
            for (e, c) in granule.cp_inv.iter().enumerate() {
                granbed_kernel::constitutive::update::check_state(c)
                    .with_context(|| format!("granule {g}, element state {e}"))?;
            }
        }
        let np = d.len(8)?;
        let pairs = (0..np)
            .map(|_| {
                let v = d.u64()?;
                Ok(GranulePair {
                    a: (v >> 32) as u32,
                    b: v as u32,
                })
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let built = d
            .vecs::<4>()?
            .into_iter()
            .map(|b| Bound {
                centre: [b[0], b[1], b[2]],
                radius: b[3],
            })
            .collect();
        let held = match version {
            2..=5 => Vec::new(),
            _ => (0..np)
                .map(|_| match d.u64()? {
                    0 => Ok(None),
                    1 => d
                        .vecs::<CONSTRAINT_FLOATS>()?
                        .into_iter()
                        .map(constraint_from)
                        .collect::<anyhow::Result<Vec<_>>>()
                        .map(Some),
                    other => bail!("unknown held-constraints flag {other}"),
                })
                .collect::<anyhow::Result<Vec<_>>>()?,
        };
        let die_normal = match version {
            // An empty window (the checkpoint of an output row's step)
            // holds no force yet: 0, so that the next row is recorded.
            2..=8 if w[0] == 0.0 => 0.0,
            2..=8 => Real::NAN,
            _ => {
                let window = d.f64()?;
                for sample in &mut samples {
                    sample.die_normal_force_n = d.f64()?;
                }
                window
            }
        };
        let (counters, counters_from_step) = match version {
            2..=6 => (PhaseTimes::default(), t[1].to_bits()),
            _ => {
                let [predict_s, contact_s, correct_s] = <[f64; 3]>::try_from(d.f64s()?)
                    .map_err(|_| anyhow::anyhow!("bad phase times"))?;
                let mut n = [0u64; 7];
                for x in &mut n {
                    *x = d.u64()?;
                }
                let counters = PhaseTimes {
                    predict_s,
                    contact_s,
                    correct_s,
                    sweeps: n[0],
                    rigid_granule_steps: n[1],
                    steps: n[2],
                    list_builds: n[3],
                    anchor_renewals: n[4],
                    pair_searches: n[5],
                };
                (counters, n[6])
            }
        };
        let unloading = match version {
            2..=9 => None,
            _ => match d.u64()? {
                0 => None,
                1 => {
                    let rows = d.rows_after(samples.last())?;
                    Some(Unloading {
                        samples: rows,
                        lift_off_strain: d.f64()?,
                        wall_time_s: d.f64()?,
                        cut_short: None,
                    })
                }
                other => bail!("unknown unloading flag {other}"),
            },
        };
        let withdrawal = match version {
            2..=10 => None,
            _ => match d.u64()? {
                0 => None,
                1 => {
                    let turn_steps = d.u64()?;
                    let next_row = d.f64()?;
                    let wall_time_s = d.f64()?;
                    let w = <[f64; WINDOW_FLOATS]>::try_from(d.f64s()?)
                        .map_err(|_| anyhow::anyhow!("bad withdrawal window"))?;
                    let window = window_from(w, d.f64()?);
                    let rows = d.rows_after(samples.last())?;
                    Some(WithdrawalProgress {
                        turn_steps,
                        rows,
                        window,
                        next_row,
                        wall_time_s,
                    })
                }
                other => bail!("unknown withdrawal flag {other}"),
            },
        };
        if !d.0.is_empty() {
            bail!("checkpoint has {} bytes after its end", d.0.len());
        }
        Ok(Self {
            progress: Progress {
                scene_toml,
                die: DieScene {
                    die_radius_m,
                    bed_height_m,
                    punch_speed_m_s,
                },
                pour_wall_time_s,
                compression_wall_time_s,
                samples,
                window: window_from(w, die_normal),
                next_output,
                snapshots_done,
                counters,
                counters_from_step,
                unloading,
                withdrawal,
            },
            state: AssemblyState {
                time: t[0],
                steps: t[1].to_bits(),
                dt: [t[2], t[3]],
                energies,
                undeformed_step,
                granules,
                pairs,
                built,
                held,
            },
        })
    }

    /// Writes the checkpoint to `dir/checkpoint.bin` atomically: a
    /// temporary file in the same directory, flushed and synced, then
    /// renamed over the old one (a crash leaves the old or the new file,
    /// never a torn one).
    pub fn write(&self, dir: &Path) -> anyhow::Result<PathBuf> {
        self.write_as(dir, FILE_NAME)
    }

    /// [`Checkpoint::write`] to `dir/name` (the withdrawal's own file,
    /// [`WITHDRAWAL_FILE_NAME`]).
    ///
    /// The payload is streamed after a header whose length and checksum are
    /// filled in once it is written (in 1 MiB blocks, hashed as they go).
    pub fn write_as(&self, dir: &Path, name: &str) -> anyhow::Result<PathBuf> {
        let path = dir.join(name);
        let tmp = dir.join(format!("{name}.tmp"));
        let mut file = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot create `{}`", tmp.display()))?;
        let mut head = Vec::with_capacity(HEAD_BYTES);
        head.extend_from_slice(MAGIC);
        head.extend_from_slice(&VERSION.to_le_bytes());
        head.resize(HEAD_BYTES, 0);
        let written = file.write_all(&head).and_then(|()| {
            let mut e = Enc::new(&mut file);
            self.encode(&mut e);
            let (len, sum) = e.finish()?;
            file.seek(std::io::SeekFrom::Start(LENGTH_AT))?;
            file.write_all(&len.to_le_bytes())?;
            file.write_all(&sum.to_le_bytes())?;
            file.sync_all()
        });
        drop(file);
        if let Err(e) = written {
            // A half-written file (up to the state's size) is of no use to
            // a resume: not left behind.
            let _ = std::fs::remove_file(&tmp);
            return Err(anyhow::Error::new(e).context(format!("cannot write `{}`", tmp.display())));
        }
        std::fs::rename(&tmp, &path)
            .with_context(|| format!("cannot move the checkpoint to `{}`", path.display()))?;
        Ok(path)
    }

    /// Reads `dir/checkpoint.bin`, checking the magic, the version and the
    /// checksum.
    pub fn read(dir: &Path) -> anyhow::Result<Self> {
        Self::read_from(dir, FILE_NAME)
    }

    /// [`Checkpoint::read`] of `dir/name`.
    pub fn read_from(dir: &Path, name: &str) -> anyhow::Result<Self> {
        let path = dir.join(name);
        let bytes = std::fs::read(&path)
            .with_context(|| format!("cannot read checkpoint `{}`", path.display()))?;
        let bad =
            |why: &str| anyhow::anyhow!("`{}` is not a usable checkpoint: {why}", path.display());
        if bytes.len() < HEAD_BYTES || &bytes[..16] != MAGIC {
            return Err(bad("no granbed checkpoint header"));
        }
        let at = LENGTH_AT as usize;
        let version = u32::from_le_bytes(bytes[16..at].try_into().unwrap_or_default());
        if !(OLDEST_VERSION..=VERSION).contains(&version) {
            return Err(bad(&format!(
                "format version {version}, this build reads {OLDEST_VERSION} to {VERSION}"
            )));
        }
        let len = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or_default());
        let sum = u64::from_le_bytes(bytes[at + 8..HEAD_BYTES].try_into().unwrap_or_default());
        let payload = &bytes[HEAD_BYTES..];
        if (payload.len() as u64) < len {
            return Err(bad(&format!(
                "truncated ({} of its {len} payload bytes)",
                payload.len()
            )));
        }
        if payload.len() as u64 > len {
            return Err(bad(&format!(
                "{} bytes after its {len}-byte payload (appended to, or two files in one)",
                payload.len() as u64 - len
            )));
        }
        if fnv1a(payload) != sum {
            return Err(bad("checksum mismatch"));
        }
        Self::from_payload(payload, version).map_err(|e| bad(&format!("{e:#}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The encoder writes exactly the bytes it is given, in order, across
    /// the boundaries of its blocks, and returns their length and FNV-1a
    /// checksum, which the reader checks against the whole payload.
    #[test]
    fn the_encoder_streams_what_it_counts_and_hashes() {
        let floats: Vec<f64> = (0..400_000).map(|k| f64::from(k) * 0.37 - 5.0).collect();
        let text = b"granules = 30";
        let mut out = Vec::new();
        let mut e = Enc::new(&mut out);
        e.bytes(text);
        e.f64s(&floats);
        e.u64(7);
        let (len, sum) = e.finish().unwrap();
        let mut expected = (text.len() as u64).to_le_bytes().to_vec();
        expected.extend_from_slice(text);
        expected.extend_from_slice(&(floats.len() as u64).to_le_bytes());
        for x in &floats {
            expected.extend_from_slice(&x.to_bits().to_le_bytes());
        }
        expected.extend_from_slice(&7u64.to_le_bytes());
        assert!(expected.len() > 3 * Enc::BLOCK, "crosses block boundaries");
        assert_eq!(out, expected);
        assert_eq!(len, expected.len() as u64);
        assert_eq!(sum, fnv1a(&expected));
    }

    /// A write that fails is returned by `finish`, not lost, whatever was
    /// encoded after it, and nothing more is written after it.
    #[test]
    fn the_encoder_returns_its_first_write_error() {
        /// Fails its first write ("disk full"), and any later one
        /// differently; counts the calls.
        struct Full(usize);
        impl std::io::Write for Full {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                self.0 += 1;
                Err(std::io::Error::other(if self.0 == 1 {
                    "disk full"
                } else {
                    "written after a failure"
                }))
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let mut out = Full(0);
        let mut e = Enc::new(&mut out);
        e.f64s(&vec![1.0; 300_000]);
        e.u64(1);
        assert_eq!(e.finish().unwrap_err().to_string(), "disk full");
        assert_eq!(out.0, 1, "writes after the first failure");
    }

    /// A held constraint reads back as written, its floats to the bit, on
    /// either side, ordinary or a watch; another side value is refused.
    #[test]
    fn held_constraints_round_trip_with_their_kind() {
        for side in [Side::A, Side::B] {
            for watch in [false, true] {
                let c = Constraint {
                    side,
                    slave: 7,
                    quad: 3,
                    weights: [0.1, 0.2, 0.3, 0.4],
                    normal: [0.0, 0.6, 0.8],
                    gap: -1e-7,
                    watch,
                };
                assert_eq!(constraint_from(constraint_to(&c)).unwrap(), c);
            }
        }
        let mut v = constraint_to(&Constraint::default());
        v[0] = 4.0;
        assert!(constraint_from(v).is_err());
    }
}
