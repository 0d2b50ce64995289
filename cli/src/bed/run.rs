//! The bed compression run: pour the spheres ([`pour`], or take a
//! [`Packing`] poured before), put a granule mesh at every centre, press the upper punch to the final strain and sample the
//! time-averaged state every output interval. Nothing here depends on
//! clap, so the tests drive exactly this code.

use core::ops::ControlFlow;
use core::sync::atomic::{AtomicBool, Ordering};
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::analysis::bed::{
    GranuleShape, bed_density, coordination_number, coordination_number_with_walls, granule_shape,
    surface_geometry,
};
use granbed_kernel::analysis::quasi_static::ImposedCompression;
use granbed_kernel::dem::pour::{PourError, PourParams, PourStatus};

use super::checkpoint::{self, Checkpoint};
use super::scene::Scene;
use crate::assembly::die::{DieScene, placements, wall_index};
use crate::assembly::{
    Assembly, AssemblyError, AssemblyParams, AssemblyState, Energies, PhaseTimes,
};
use crate::model::OwnedReference;
use crate::pack::run::run_pour;

/// The default of the scene's `sweep_tolerance`: a further contact sweep
/// runs while the last one left a granule–granule gap deeper than this
/// fraction of the element size (the shortest surface edge), up to the
/// scene's `contact_sweeps`.
///
/// **Choice, by measurement** (30 coarse B2 granules to 30 %, one thread;
/// BENCHMARKS.md): 3 sweeps with a 0.05 µm tolerance left overlaps of
/// 1.8 % of the element (issue #9 allows 1 %); up to 10 sweeps with this
/// tolerance leave 0.23 % for 16 % more wall time (0.2 %: 0.10 % for
/// +43 %; 0.05 µm: 0.017 % for +83 %). Each sweep leaves about a third of
/// the gap the last one found. That bed never needs more than 10; a C3
/// bed at 55–60 % does: with at most 10 it overlapped by 1.02 %, with 25
/// by 0.43 % (the scene's default cap is 25).
///
/// This is the tolerance of a scene file without `sweep_tolerance` (from
/// before it was a field); the published scene has 0.01 since session 18
/// (a fifth to a quarter fewer sweeps late in a dense bed, P(C) within the
/// noise floor; BENCHMARKS.md).
pub const SWEEP_TOLERANCE_REL: Real = 0.005;

/// One output row: averages over the interval that ends at `strain`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BedSample {
    /// Time, s.
    pub time_s: Real,
    /// Axial strain C = (H0 − H)/H0 at the end of the interval, where the
    /// row's instantaneous fields (densities, Heywood, energies) were taken.
    pub strain: Real,
    /// The interval's mean axial strain ([`interval_mean_strain`]): the
    /// strain its averaged fields (forces, pressures, coordination) belong
    /// to, and the one the Kawakita and Heckel fits pair with P. Derived
    /// from the rows' strains and steps, not stored in checkpoints.
    pub mean_strain: Real,
    /// Upper-punch force, N (interval average).
    pub upper_force_n: Real,
    /// Lower-punch force, N (interval average).
    pub lower_force_n: Real,
    /// Axial (z) friction force of the die wall on the granules, N
    /// (interval average; positive upwards).
    pub die_friction_z_n: Real,
    /// Σ normal (radial) force of the die wall on the granules, N
    /// (interval average): the die-wall pressure's resultant. NaN where
    /// not recorded (checkpoints before version 9).
    pub die_normal_force_n: Real,
    /// Upper-punch pressure F/(π R_d²), Pa.
    pub upper_pressure_pa: Real,
    /// Lower-punch pressure, Pa.
    pub lower_pressure_pa: Real,
    /// Coordination number 2 N_pp / N (interval average).
    pub coordination: Real,
    /// Coordination number counting granule–wall contacts too,
    /// (2 N_pp + N_pw)/N with N_pw the (granule, wall) pairs in contact.
    pub coordination_with_walls: Real,
    /// Mean granule relative density η0 V0/V (arithmetic mean).
    pub relative_density_mean: Real,
    /// Σ solid volume / Σ granule volume.
    pub relative_density_solid: Real,
    /// Mean Heywood coefficient d_V S/V.
    pub heywood_dv: Real,
    /// Mean Heywood coefficient d S/V with the nominal diameter d.
    pub heywood_d: Real,
    /// Smallest element Jacobian ratio in the interval.
    pub min_jacobian: Real,
    /// Smallest Gauss-point Jacobian ratio of any element at the end of the
    /// interval (≤ 0: an element folded; the centre's `min_jacobian` can
    /// miss it).
    pub min_gauss_jacobian: Real,
    /// Largest nodal speed in the interval, m/s.
    pub max_node_speed_m_s: Real,
    /// Deepest granule–granule overlap on the positions at the end of the
    /// interval (a detection pass on x_n), m; 0 if none.
    pub penetration_m: Real,
    /// Steps so far.
    pub steps: u64,
    /// Energy ledger so far (elastic energy at this instant).
    pub energies: Energies,
    /// Kinetic energy at this instant relative to the compression the
    /// punches impose ([`Assembly::kinetic_relative_to`]), J; NaN where not
    /// recorded (checkpoints before version 5).
    pub kinetic_relative_j: Real,
}

/// The mean axial strain over the steps of the output interval that ends
/// at `strain` after `steps` steps, the one before it ending at
/// `previous` = (strain, steps) (`None` for the first row, at t = 0,
/// whose forces are instantaneous: its own strain).
///
/// The interval's forces are Σ F(t_k) Δt_k / Σ Δt_k over its steps k, each
/// force taken at the step's end t_k. The strain that belongs to them is
/// the same mean of C(t_k). The punch moves at constant speed, so C is
/// linear in t, and with the n steps of the interval taken as equal the
/// mean is C_prev + (C − C_prev)(n + 1)/(2n): half an interval before its
/// end, plus half a step. The time step changes by little within an
/// interval (the stable step of a slowly deforming bed), and unequal steps
/// move the mean by a second-order amount, Var(Δt)/(2⟨Δt⟩) in time: for
/// steps growing steadily by 10 % over the interval, 4·10⁻⁴ of a step's
/// strain. Pairing the averaged pressure with the interval's end strain
/// instead would put every point of P(C) half an interval too far (0.0025
/// at the default 0.005), which biases the Kawakita and Heckel fits by one
/// to two per cent (physics.md §7 leaves the pairing open).
pub fn interval_mean_strain(previous: Option<(Real, u64)>, strain: Real, steps: u64) -> Real {
    match previous {
        Some((before, from)) if steps > from => {
            let n = (steps - from) as Real;
            before + (strain - before) * (n + 1.0) / (2.0 * n)
        }
        _ => strain,
    }
}

/// Sets every sample's [`BedSample::mean_strain`] from its own and the
/// previous sample's strain and steps ([`interval_mean_strain`]).
pub fn set_mean_strains(samples: &mut [BedSample]) {
    set_mean_strains_after(None, samples);
}

/// [`set_mean_strains`] for rows that follow the row `after` (the
/// withdrawal's after the loading's last).
pub fn set_mean_strains_after(after: Option<&BedSample>, samples: &mut [BedSample]) {
    let mut previous = after.map(|s| (s.strain, s.steps));
    for s in samples {
        s.mean_strain = interval_mean_strain(previous, s.strain, s.steps);
        previous = Some((s.strain, s.steps));
    }
}

/// Output rows per output interval (`output_strain_interval`) while the
/// upper punch withdraws: the unloading takes a small fraction of the
/// loading's strain, so its curve needs closer rows.
pub const UNLOADING_ROWS_PER_INTERVAL: u32 = 10;

/// How far the upper punch withdraws at most, as nominal axial strain
/// (and never past the strain it pressed to): a bed of soft granules
/// recovers several per cent of its height (the published B2, yield strain
/// σ_y/E = 3 %: 5.7 % of H_min from C = 0.3 in the published scene, about
/// 7 % in a bed of 100 coarse granules in a 5 mm die); a bed that still
/// pushes the punch after this much is reported as not come free.
pub const MAX_WITHDRAWAL_STRAIN: Real = 0.15;

/// The upper punch counts as free of the bed once its force, averaged over
/// an output row's interval, is below this fraction of the largest it
/// carried while pressing (a compaction simulator's force resolution).
/// The bed lets go slowly: its granules' contacts soften as they unload,
/// so the force has a long tail towards zero (a bed of 100 coarse
/// granules pressed to 0.3: 1 % of the largest force 0.049 of strain after
/// the turn, and still not 0 by then).
pub const LIFT_OFF_FORCE_FRACTION: Real = 0.01;

/// What the upper punch's withdrawal after the final strain recorded
/// (scene `unload`).
#[derive(Clone, Debug, PartialEq)]
pub struct Unloading {
    /// Output rows after the final strain's row, strain falling; the last
    /// the first whose upper-punch force is below
    /// [`LIFT_OFF_FORCE_FRACTION`] of the loading's largest (lift-off).
    pub samples: Vec<BedSample>,
    /// The nominal strain where the upper punch came free of the bed: where
    /// its force crossed [`LIFT_OFF_FORCE_FRACTION`] of the loading's
    /// largest, linear between the two rows' mean strains (the first row's
    /// from the turn, with the loading's last force); NaN if it had not
    /// when the withdrawal stopped.
    pub lift_off_strain: Real,
    /// Wall time of the withdrawal, s.
    pub wall_time_s: f64,
    /// Why the withdrawal stopped before lift-off or its limit; `None` if
    /// it completed. A withdrawal cut short is not kept in the loading's
    /// checkpoint; its own ([`checkpoint::WITHDRAWAL_FILE_NAME`]), written
    /// as it goes and at an interrupt, is where a resume goes on from.
    pub cut_short: Option<CutShort>,
}

/// Why a withdrawal stopped before lift-off or its limit.
#[derive(Clone, Debug, PartialEq)]
pub enum CutShort {
    /// `RunControl::interrupt` was set; the strain the punch had reached.
    Interrupted {
        /// Nominal strain at the step the withdrawal stopped after.
        strain: Real,
    },
    /// A step failed (the assembly's error, as text).
    StepFailed(String),
    /// Its checkpoint could not be written (the error, as text): it stops
    /// there rather than go on unkept, and the loading's outputs are
    /// written as they are.
    CheckpointFailed(String),
}

impl core::fmt::Display for CutShort {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Interrupted { strain } => write!(f, "interrupted at C = {strain:.4}"),
            Self::StepFailed(e) => write!(f, "a step failed: {e}"),
            Self::CheckpointFailed(e) => write!(f, "its checkpoint could not be written: {e}"),
        }
    }
}

/// Whether a withdrawal run under the scene `then` (a checkpoint's TOML)
/// is the one `now` would run from the same state: every field the same
/// but those that do not reach the step (the fit windows, the snapshots,
/// the checkpoints' intervals, the face lists' skin, which changes no bit)
/// and the final strain (the state is past it either way).
fn withdrawal_holds(then: &str, now: &Scene) -> bool {
    Scene::from_toml(then).is_ok_and(|then| {
        Scene {
            kawakita_min_strain: now.kawakita_min_strain,
            heckel_min_strain: now.heckel_min_strain,
            snapshot_strains: now.snapshot_strains.clone(),
            checkpoint_interval_minutes: now.checkpoint_interval_minutes,
            checkpoint_strain_interval: now.checkpoint_strain_interval,
            face_list_skin: now.face_list_skin,
            final_strain: now.final_strain,
            ..then
        } == *now
    })
}

/// A row of the averaging window `w` that ends at `strain` with the
/// punches at `imposed`, after the row `previous`.
type SampleOf<'a> = dyn Fn(&mut Assembly<'_>, &Window, Option<&BedSample>, Real, ImposedCompression) -> BedSample
    + 'a;

/// Removes `dir`'s checkpoint of a withdrawal in progress, if any.
fn remove_withdrawal_checkpoint(dir: &std::path::Path) -> anyhow::Result<()> {
    let path = dir.join(checkpoint::WITHDRAWAL_FILE_NAME);
    match std::fs::remove_file(&path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove `{}`", path.display()))
        }
        _ => Ok(()),
    }
}

/// Writes a withdrawal's checkpoint from the assembly and the progress.
type SaveWithdrawal<'a> =
    dyn Fn(&Assembly<'_>, checkpoint::WithdrawalProgress) -> anyhow::Result<()> + 'a;

/// Where a withdrawal goes on from, and where it keeps its progress.
struct WithdrawalStore<'a> {
    /// A withdrawal an interrupt stopped: its progress and the assembly's
    /// state then (from [`checkpoint::WITHDRAWAL_FILE_NAME`]).
    resume: Option<(checkpoint::WithdrawalProgress, AssemblyState)>,
    /// Writes the withdrawal's checkpoint (none: no checkpoints).
    save: Option<&'a SaveWithdrawal<'a>>,
    /// Wall time between the withdrawal's checkpoints, s.
    every_s: f64,
}

/// Withdraws the upper punch of `asm`, which has just pressed the bed to
/// the last of the rows `loading`, at the punch speed, with a row every
/// 1/[`UNLOADING_ROWS_PER_INTERVAL`] of the scene's output interval, until
/// a row's upper-punch force falls below [`LIFT_OFF_FORCE_FRACTION`] of
/// the loading's largest (lift-off), or the punch has withdrawn
/// [`MAX_WITHDRAWAL_STRAIN`], or `interrupt` is set, or a step fails.
/// `observer` sees each row. With `store.resume` it goes on from there,
/// with the bits of a withdrawal never stopped; `store.save` keeps its
/// progress every `store.every_s` and when the interrupt stops it.
fn withdraw(
    asm: &mut Assembly<'_>,
    (die, scene): (&DieScene, &Scene),
    loading: &[BedSample],
    (interrupt, observer): (Option<&AtomicBool>, &mut dyn BedObserver),
    sample: &SampleOf<'_>,
    store: WithdrawalStore<'_>,
) -> anyhow::Result<Unloading> {
    let at_end = loading.last().copied().unwrap_or_default();
    let turn_steps = asm.steps();
    let free_below_n =
        LIFT_OFF_FORCE_FRACTION * loading.iter().map(|s| s.upper_force_n).fold(0.0, Real::max);
    let start = Instant::now();
    let speed = die.punch_speed_m_s;
    // At the turn, so that the punch's motion is the same whether the
    // withdrawal goes on from a checkpoint or not.
    asm.withdraw_wall(wall_index::UPPER, speed);
    let interval = scene.output_strain_interval / Real::from(UNLOADING_ROWS_PER_INTERVAL);
    let limit = at_end.strain - MAX_WITHDRAWAL_STRAIN.min(at_end.strain);
    let mut next = at_end.strain - interval;
    let (mut window, mut previous) = (Window::new(), at_end);
    // The (strain, force) the lift-off is interpolated from: the turn, with
    // the loading's last force, then each row's.
    let mut before = (at_end.strain, at_end.upper_force_n);
    let (mut samples, mut lift_off_strain, mut cut_short) = (Vec::new(), Real::NAN, None);
    let mut wall_before = 0.0;
    if let Some((progress, state)) = store.resume {
        asm.restore(&state).with_context(|| {
            format!(
                "cannot go on from {}: remove it, and --resume runs the withdrawal from the \
                 loading's end",
                checkpoint::WITHDRAWAL_FILE_NAME
            )
        })?;
        if die.strain_at_height(super::snapshots::die_geometry(asm).1)
            < scene.exact_contact_from_strain
        {
            asm.set_exact_contact_from(Real::INFINITY);
        }
        for s in &progress.rows {
            observer.withdrawal(s, progress.wall_time_s);
        }
        if let Some(&last) = progress.rows.last() {
            previous = last;
            before = (last.mean_strain, last.upper_force_n);
        }
        (samples, window, next) = (progress.rows, progress.window, progress.next_row);
        wall_before = progress.wall_time_s;
    }
    let wall = || wall_before + start.elapsed().as_secs_f64();
    let mut last_save = Instant::now();
    loop {
        if let Err(e) = asm.step() {
            cut_short = Some(CutShort::StepFailed(e.to_string()));
            break;
        }
        window.add_step(asm);
        let upper_z_m = super::snapshots::die_geometry(asm).1;
        let strain = die.strain_at_height(upper_z_m);
        // The scene's exact contact holds from a strain on: a withdrawal
        // back below it returns to the held constraints (a time-based
        // switch would keep it on for the whole withdrawal).
        if strain < scene.exact_contact_from_strain {
            asm.set_exact_contact_from(Real::INFINITY);
        }
        if strain <= next + 1e-12 || strain <= limit {
            let imposed = ImposedCompression {
                lower_z_m: 0.0,
                lower_velocity_m_s: 0.0,
                upper_z_m,
                upper_velocity_m_s: speed,
            };
            let s = sample(asm, &window, Some(&previous), strain, imposed);
            observer.withdrawal(&s, wall());
            samples.push(s);
            window = Window::new();
            while next >= strain - 1e-12 {
                next -= interval;
            }
            if s.upper_force_n < free_below_n {
                let ((c0, f0), f1) = (before, s.upper_force_n);
                // The crossing between the two (at this row if the one
                // before was below already, which only a loading that
                // ended far below its largest force gives).
                let t = if f0 > f1 {
                    ((f0 - free_below_n) / (f0 - f1)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                lift_off_strain = c0 + t * (s.mean_strain - c0);
                break;
            }
            if strain <= limit {
                break;
            }
            previous = s;
            before = (s.mean_strain, s.upper_force_n);
        }
        let interrupted = interrupt.is_some_and(|f| f.load(Ordering::SeqCst));
        if let Some(save) = store.save
            && (interrupted || last_save.elapsed().as_secs_f64() >= store.every_s)
        {
            let progress = checkpoint::WithdrawalProgress {
                turn_steps,
                rows: samples.clone(),
                window,
                next_row: next,
                wall_time_s: wall(),
            };
            if let Err(e) = save(asm, progress) {
                cut_short = Some(CutShort::CheckpointFailed(format!("{e:#}")));
                break;
            }
            last_save = Instant::now();
        }
        if interrupted {
            cut_short = Some(CutShort::Interrupted { strain });
            break;
        }
    }
    Ok(Unloading {
        samples,
        lift_off_strain,
        wall_time_s: wall(),
        cut_short,
    })
}

/// What a run produced. A run stopped by a kernel error keeps the samples
/// so far and holds the error.
#[derive(Debug)]
pub struct BedRun {
    /// Samples in time order, the first at t = 0.
    pub samples: Vec<BedSample>,
    /// Initial bed height H0, m.
    pub bed_height_m: Real,
    /// Die radius, m.
    pub die_radius_m: Real,
    /// Granules.
    pub granules: usize,
    /// Hexes per granule.
    pub hexes_per_granule: usize,
    /// Element size: the shortest surface edge of the reference mesh, m.
    pub element_size_m: Real,
    /// Steps completed.
    pub steps: u64,
    /// Strain at the end of the last step (the last sample's, unless the
    /// run stopped between two output rows).
    pub strain_reached: Real,
    /// Granule-element evaluations (steps × granules × hexes).
    pub element_steps: u64,
    /// Wall time of the pour, s.
    pub pour_wall_time_s: f64,
    /// Wall time of the compression, s (all segments of a resumed run).
    pub wall_time_s: f64,
    /// Wall time by phase of the compression and the contact counters,
    /// over the steps from [`BedRun::counters_from_step`] on (all segments
    /// of a resumed run: the checkpoint carries them).
    pub phase_times: PhaseTimes,
    /// The first step [`BedRun::phase_times`] covers: 0, the whole run,
    /// unless the run was resumed from a checkpoint older than format 7,
    /// which did not carry the counters.
    pub counters_from_step: u64,
    /// Solid volume of all granules, m³ (N η0 V0 with the reference mesh's
    /// volume V0; constant): the numerator of the bed's solid fraction.
    pub solid_volume_m3: Real,
    /// Threads of the pool the run used.
    pub threads: usize,
    /// True if the run stopped at `RunControl::stop_at_strain`.
    pub stopped: bool,
    /// True if the run stopped because [`RunControl::interrupt`] was set
    /// (SIGINT/SIGTERM): after the step it was in, with a checkpoint.
    pub interrupted: bool,
    /// True if the run was resumed from a checkpoint already at or past
    /// the final strain (no step taken).
    pub resumed_past_end: bool,
    /// Warnings about the run that its samples do not show, for stderr and
    /// `summary.json` (the summary adds those it derives from the samples).
    pub warnings: Vec<String>,
    /// The error that stopped the run, if any.
    pub error: Option<AssemblyError>,
    /// With an error: the strain of the newest checkpoint on disk (the
    /// state at the last output row before the failure, or a later
    /// periodic checkpoint), if checkpoints are written.
    pub checkpoint_strain: Option<Real>,
    /// The rate check (`granbed-cli bed --rate-check`): the relative L2
    /// change of P(C) when the same bed is pressed at half the punch speed
    /// (None: not checked).
    pub rate_change_rel: Option<Real>,
    /// The withdrawal's rate check (`--rate-check` on a scene that
    /// unloads): the withdrawal's figures of the same bed pressed and
    /// withdrawn at half the punch speed (None: not checked).
    pub half_speed_unloading: Option<super::unloading::UnloadingSummary>,
    /// What variable mass scaling did (scene `time_step_floor`).
    pub added_mass: AddedMass,
    /// The overlap by geometry at the end of the run, if
    /// [`RunControl::check_final_overlap`] asked for it.
    pub hidden_overlap: Option<HiddenOverlap>,
    /// Each granule where the run ended, in granule order (empty for a run
    /// stopped by an error: its last state is no state to show).
    pub final_granules: Vec<GranuleAtEnd>,
    /// The upper punch's withdrawal after the final strain (scene
    /// `unload`; `None` for a run that did not reach its final strain).
    /// The run's other figures (the steps, timings, the final state) are
    /// those of the loading.
    pub unloading: Option<Unloading>,
}

/// A granule where a run ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GranuleAtEnd {
    /// Its centre of mass, m.
    pub centre_m: [Real; 3],
    /// Its relative density η0 V0/V (NaN for a degenerate surface).
    pub relative_density: Real,
}

/// Every granule of `asm` (meshes `mesh`, nominal diameter `d_m`) as
/// [`GranuleAtEnd`]: its relative density as the snapshots have it.
fn granules_at_end(asm: &Assembly<'_>, mesh: &OwnedReference, d_m: Real) -> Vec<GranuleAtEnd> {
    let fields = super::snapshots::granule_fields(asm, mesh, d_m);
    super::snapshot_tables::centres_of_mass(asm)
        .into_iter()
        .zip(fields.relative_density)
        .map(|(centre_m, relative_density)| GranuleAtEnd {
            centre_m,
            relative_density,
        })
        .collect()
}

/// The granules' overlap by geometry at the end of a run
/// ([`Assembly::hidden_overlap`]), and what measuring it cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HiddenOverlap {
    /// The deepest surface node inside another granule (depth 0: none).
    pub deepest: crate::assembly::overlap::Overlap,
    /// Wall time of the measurement, s (not in [`BedRun::wall_time_s`]).
    pub wall_time_s: f64,
}

impl BedRun {
    /// Where an interrupted run stopped, for its messages: the strain and
    /// step of its last step, and the strain of its outputs' last row when
    /// that is an earlier one (rows are written every output interval, so
    /// the summary and the CSVs end there, not at the step).
    pub fn stopped_at(&self) -> String {
        let mut at = format!("C = {:.4}, step {}", self.strain_reached, self.steps);
        if let Some(last) = self.samples.last()
            && last.strain < self.strain_reached
        {
            at.push_str(&format!(" (the outputs' last row: C = {:.4})", last.strain));
        }
        at
    }
}

#[cfg(test)]
impl BedRun {
    /// A finished run with these `samples` of one granule of one hex in a
    /// bed and die of unit size, nothing else recorded: for unit tests of
    /// what is made of a run's samples.
    /// Their mean strains are set as a run sets them: with no steps
    /// recorded, each row's own strain.
    pub(crate) fn of_samples(mut samples: Vec<BedSample>) -> Self {
        set_mean_strains(&mut samples);
        let strain_reached = samples.last().map_or(0.0, |s| s.strain);
        Self {
            samples,
            bed_height_m: 1.0,
            die_radius_m: 1.0,
            granules: 1,
            hexes_per_granule: 1,
            element_size_m: 1.0,
            steps: 0,
            strain_reached,
            element_steps: 0,
            pour_wall_time_s: 0.0,
            wall_time_s: 0.0,
            rate_change_rel: None,
            half_speed_unloading: None,
            phase_times: Default::default(),
            counters_from_step: 0,
            solid_volume_m3: 1.0,
            threads: 1,
            stopped: false,
            interrupted: false,
            resumed_past_end: false,
            warnings: Vec::new(),
            error: None,
            checkpoint_strain: None,
            added_mass: Default::default(),
            hidden_overlap: None,
            final_granules: Vec::new(),
            unloading: None,
        }
    }
}

/// What variable mass scaling ([`crate::assembly::AssemblyParams::time_step_floor`])
/// did to a run, at its end.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct AddedMass {
    /// The undeformed granule's stable step, s (what the floor is a
    /// fraction of; before the damping's reduction).
    pub undeformed_step_s: Real,
    /// Granules whose masses were raised.
    pub granules_scaled: usize,
    /// The largest factor put on a granule's masses (1: none).
    pub max_factor: Real,
    /// Mass added, as a fraction of the bed's mass before it.
    pub added_mass_rel: Real,
}

impl AddedMass {
    /// What `asm` holds now.
    pub fn of(asm: &Assembly<'_>) -> Self {
        let k = asm.mass_factors();
        Self {
            undeformed_step_s: asm.undeformed_step(),
            granules_scaled: k.iter().filter(|&&k| k > 1.0).count(),
            max_factor: k.iter().copied().fold(1.0, Real::max),
            added_mass_rel: asm.added_mass_fraction(),
        }
    }
}

/// The time-averaging window of the samples (integrals over the open
/// output interval).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Window {
    /// Length, s.
    pub time: Real,
    /// ∫ upper, lower punch force and die friction z dt, N s.
    pub impulse: [Real; 3],
    /// ∫ Σ die-wall normal force dt, N s (NaN: the window of a checkpoint
    /// before version 9, which did not record it).
    pub die_normal: Real,
    /// ∫ pairs in contact dt, s.
    pub pairs: Real,
    /// ∫ (granule, wall) contacts dt, s.
    pub walls: Real,
    /// Smallest Jacobian ratio.
    pub min_j: Real,
    /// Largest nodal speed, m/s.
    pub max_speed: Real,
}

impl Window {
    /// An empty window.
    pub fn new() -> Self {
        Self {
            min_j: Real::INFINITY,
            ..Self::default()
        }
    }

    /// Adds the step `asm` has just taken.
    fn add_step(&mut self, asm: &Assembly<'_>) {
        let last = asm.last();
        let dt = last.dt;
        self.time += dt;
        self.impulse[0] += last.walls[wall_index::UPPER].normal * dt;
        self.impulse[1] += last.walls[wall_index::LOWER].normal * dt;
        self.impulse[2] += last.walls[wall_index::DIE].tangential[2] * dt;
        self.die_normal += last.walls[wall_index::DIE].normal * dt;
        self.pairs += asm.contact().pairs_in_contact() as Real * dt;
        self.walls += last.wall_contacts as Real * dt;
        self.min_j = self.min_j.min(last.min_j);
        self.max_speed = self.max_speed.max(last.max_node_speed_m_s);
    }
}

/// Bed geometry from every granule's current surface (physics.md §7.5–6):
/// (η arithmetic mean, Σsolid/ΣV, mean α_SV with d_V, mean α_SV with `d`).
/// A degenerate granule surface gives NaN (reported, never a panic).
fn geometry(asm: &Assembly<'_>, mesh: &OwnedReference, eta0: Real, d: Real) -> [Real; 4] {
    let v0 = surface_geometry(&mesh.positions, &mesh.quads).map_or(Real::NAN, |(_, v)| v);
    let shapes: Option<Vec<GranuleShape>> = asm
        .granules()
        .iter()
        .map(|g| granule_shape(&g.x, &mesh.quads, eta0, v0, d).ok())
        .collect();
    let Some(shapes) = shapes else {
        return [Real::NAN; 4];
    };
    let n = shapes.len() as Real;
    let density = bed_density(&shapes);
    [
        density.map_or(Real::NAN, |b| b.arithmetic),
        density.map_or(Real::NAN, |b| b.solid_over_volume),
        shapes.iter().map(|s| s.heywood_dv).sum::<Real>() / n,
        shapes.iter().map(|s| s.heywood_fixed).sum::<Real>() / n,
    ]
}

/// Sees the run as it goes: every sample (with the wall time since the
/// start of the compression), and the assembly at each snapshot strain.
pub trait BedObserver {
    /// A new output row.
    fn sample(&mut self, sample: &BedSample, elapsed_s: f64);
    /// The state when the strain first reaches `strain`, one of the
    /// scene's `snapshot_strains` (and at t = 0 for a strain of 0), and at
    /// the end of a run that reached its final strain, at that strain,
    /// if the list has none that high. An error stops the run; mid-run,
    /// after a checkpoint of the step (`--resume` writes the snapshot).
    fn snapshot(
        &mut self,
        strain: Real,
        assembly: &Assembly<'_>,
        mesh: &OwnedReference,
    ) -> anyhow::Result<()>;

    /// The pour's state at one of its rest checks, `elapsed_s` into it
    /// (for progress; a fresh run's pour only). Nothing by default.
    fn pour(&mut self, _status: &PourStatus, _elapsed_s: f64) {}

    /// A row of the upper punch's withdrawal after the final strain,
    /// `elapsed_s` into it (for progress). Nothing by default.
    fn withdrawal(&mut self, _row: &BedSample, _elapsed_s: f64) {}
}

/// A poured bed: the hand-over from the pour to the compression, made
/// once by [`pour`] and usable by several runs (`bed --types`).
#[derive(Clone, Debug, PartialEq)]
pub struct Packing {
    /// Sphere centres, m.
    pub centres: Vec<[Real; 3]>,
    /// Sphere radius, m.
    pub radius_m: Real,
    /// Die radius, m.
    pub die_radius_m: Real,
    /// Wall time of the pour, s.
    pub wall_time_s: f64,
}

/// Pours the bed of `scene` (its granule type sets the sphere density).
/// An error names why the pour failed.
///
/// `on_check` sees the pour's state at each of its rest checks, with the
/// wall time so far, s. Once `interrupt` is set, the pour stops at its next
/// rest check (every [`crate::pack::run::CHECK_EVERY`] steps, a fraction
/// of a second) with [`crate::signal::Interrupted`]: nothing was
/// compressed, so there is nothing to keep.
pub fn pour(
    scene: &Scene,
    interrupt: Option<&AtomicBool>,
    on_check: &mut dyn FnMut(&PourStatus, f64),
) -> anyhow::Result<Packing> {
    let material = scene.material()?;
    let pour = pour_params(scene, &material);
    let start = Instant::now();
    let poured = run_pour(pour, &mut |s, t| {
        on_check(s, t);
        if interrupt.is_some_and(|f| f.load(Ordering::SeqCst)) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .map_err(anyhow::Error::new)?;
    match poured.error {
        None => {}
        Some(PourError::Stopped { time, steps }) => {
            return Err(anyhow::Error::new(crate::signal::Interrupted(format!(
                "interrupted during the pour ({steps} steps, {time:.4} s simulated): nothing was \
                 compressed, and there is nothing to resume (no checkpoint written)"
            ))));
        }
        Some(e) => return Err(anyhow::Error::new(e).context("the pour did not come to rest")),
    }
    Ok(Packing {
        centres: poured.positions,
        radius_m: pour.radius,
        die_radius_m: pour.die_radius,
        wall_time_s: start.elapsed().as_secs_f64(),
    })
}

/// How a run starts and when it writes checkpoints or stops early.
#[derive(Clone, Debug, Default)]
pub struct RunControl {
    /// Continue from this checkpoint instead of pouring.
    pub resume: Option<Checkpoint>,
    /// Compress this packing instead of pouring (ignored with `resume`);
    /// it must have the scene's granule count, granule and die diameter.
    pub packing: Option<Packing>,
    /// Directory for checkpoints (none: no checkpoints).
    pub checkpoint_dir: Option<PathBuf>,
    /// Stop (after a checkpoint) once the strain reaches this.
    pub stop_at_strain: Option<Real>,
    /// Stop (after the current step, with a checkpoint) once this is set:
    /// the CLI passes [`crate::signal::INTERRUPT`], which its SIGINT and
    /// SIGTERM handler sets. A fresh run's pour stops at its next rest
    /// check ([`pour`]); a run that finds it set after the pour stops
    /// before its first step, both with [`crate::signal::Interrupted`].
    pub interrupt: Option<&'static AtomicBool>,
    /// Measure the granules' overlap by geometry at the end of the run
    /// ([`Assembly::hidden_overlap`], into [`BedRun::hidden_overlap`]):
    /// the check of the contact detection, once per run (3.9 s on 2
    /// threads for the default scene's 1000 granules at C = 0.25,
    /// BENCHMARKS.md). Not after an error or an interrupt.
    pub check_final_overlap: bool,
}

/// The pour's parameters for `scene`.
pub(crate) fn pour_params(
    scene: &Scene,
    material: &granbed_kernel::material::Material,
) -> PourParams {
    let radius = scene.radius_m();
    let mut pour = PourParams::standard(material.density0, scene.seed);
    let scale = radius / pour.radius;
    pour.granules = scene.granules;
    pour.radius = radius;
    pour.lattice_spacing *= scale;
    pour.jitter *= scale;
    pour.skin *= scale;
    pour.die_radius = 0.5e-3 * scene.die_diameter_mm;
    pour.friction_particle = material.params.friction;
    pour.friction_wall = material.params.friction;
    pour
}

/// The assembly's parameters for `scene` on its granule `mesh`: every
/// numerical field of the scene, lengths given as fractions of the element
/// size (`mesh.shortest_surface_edge()`) made metres. All but the time of
/// the exact-contact strain (`exact_contact_from_s`, left at the
/// standard's), which needs the die.
pub fn assembly_params(scene: &Scene, mesh: &OwnedReference) -> anyhow::Result<AssemblyParams> {
    let mut params = AssemblyParams::standard(scene.material()?, scene.element_settings()?);
    let element = mesh.shortest_surface_edge();
    params.damping_ratio = scene.damping_ratio;
    params.contact_sweeps = scene.contact_sweeps;
    params.sweep_tolerance_m = scene.sweep_tolerance * element;
    params.exact_sweep_tolerance_m = scene.exact_sweep_tolerance() * element;
    params.mass_scaling = scene.mass_scaling;
    params.selective_mass_scaling = scene.selective_mass_scaling;
    params.selective_mass_ratio = scene.selective_mass_ratio;
    params.time_step_safety = scene.time_step_safety;
    params.time_step_floor = scene.time_step_floor;
    params.max_mass_factor = scene.max_mass_factor;
    params.rigid_until_touched = scene.rigid_until_touched;
    params.local_sweeps = scene.local_sweeps;
    params.hold_constraints = scene.hold_constraints;
    params.contact_search_interval = scene.contact_search_interval;
    params.contact.capture = scene.contact_capture * element;
    params.contact.reproject_slide = scene.held_reprojection * element;
    params.contact.watch_beside = scene.held_reprojection.is_finite();
    params.contact.nearest_penetrated_face = scene.nearest_penetrated_face;
    params.face_list_skin = scene.face_list_skin;
    params.max_node_speed_m_s = scene.watchdog_speed_ratio * scene.punch_speed_m_s;
    params.kinetic_energy_limit = scene.watchdog_energy_ratio;
    Ok(params)
}

/// Refuses `scene` (a usage error naming its fields) if it could not
/// finish: its granules' own buffers exceed the machine's memory
/// (`memory_refusal`), or it would take more than [`MAX_STEPS`]
/// (`run_length`). `run_bed` checks this before its pour; a `--types`
/// series checks every member before the one pour they share.
pub fn check_feasible(scene: &Scene) -> anyhow::Result<()> {
    let mesh = scene.granule_mesh()?;
    let points = scene.element_settings()?.points_per_element();
    check_feasible_on(scene, &mesh, &scene.material()?, points)
}

/// [`check_feasible`] with the mesh, material and integration points per
/// element already made.
fn check_feasible_on(
    scene: &Scene,
    mesh: &OwnedReference,
    material: &granbed_kernel::material::Material,
    points: usize,
) -> anyhow::Result<()> {
    let need = scene.granules as u64 * crate::model::GranuleStore::bytes_for(mesh, points);
    if let Some(message) =
        machine_memory_bytes().and_then(|total| memory_refusal(scene, need, total))
    {
        return Err(crate::error::InputError(message).into());
    }
    if let Some(message) = run_length(scene, mesh, material).refusal(
        MAX_STEPS,
        "the `[material]` (youngs_modulus_pa, poisson_ratio, true_density_kg_m3, eta0), \
         mass_scaling, time_step_safety, mesh, granules, diameter_mm, die_diameter_mm, \
         punch_speed_m_s and final_strain",
    ) {
        return Err(crate::error::InputError(message).into());
    }
    Ok(())
}

/// The most steps a bed run may take (about 10⁴ times the published
/// scene's 7 723, which take 19 minutes on two cores; the slowest punch
/// allowed, `MIN_PUNCH_SPEED_M_S`, with physical masses, about 2·10⁷).
pub const MAX_STEPS: f64 = 1e8;

/// An estimate of `scene`'s steps before its pour: the undeformed
/// granule's element estimate of the stable step (which the run's global
/// estimate exceeds by about a third, physics.md §4.2) with the masses'
/// scaling, over the time the punch takes to the final strain of a bed at
/// a packing fraction of 0.6 (poured beds: 0.55–0.64).
fn run_length(
    scene: &Scene,
    mesh: &OwnedReference,
    material: &granbed_kernel::material::Material,
) -> crate::run_length::RunLength {
    let wave_speed_m_s = granbed_kernel::granule::timestep::wave_speed(material);
    let time_step_s = granbed_kernel::granule::timestep::element_time_step(
        &mesh.view(),
        material,
        &mesh.positions,
        scene.time_step_safety,
    )
    .map_or(Real::NAN, |dt| dt * scene.mass_scaling.sqrt());
    let radius = scene.radius_m();
    let die_radius = 0.5e-3 * scene.die_diameter_mm;
    let solid = scene.granules as Real * 4.0 / 3.0 * core::f64::consts::PI * radius.powi(3);
    let height = solid / (0.6 * core::f64::consts::PI * die_radius * die_radius);
    crate::run_length::RunLength {
        duration_s: scene.final_strain * height / scene.punch_speed_m_s,
        time_step_s,
        wave_speed_m_s,
    }
}

/// This machine's memory, bytes (Linux `/proc/meminfo` MemTotal), or
/// `None` where it cannot be read.
fn machine_memory_bytes() -> Option<u64> {
    crate::output::proc_kib_field("/proc/meminfo", "MemTotal:")
}

/// Why `scene` cannot run on a machine of `total` bytes, if its granules'
/// own buffers, `need` bytes ([`crate::model::GranuleStore::bytes_for`]
/// each: a lower bound, the contact lists and outputs come on top — the
/// published scene peaks at about 3.4 times it), do not fit: a scene of
/// many granules on a fine mesh was killed for want of memory after its
/// pour, without a message.
fn memory_refusal(scene: &Scene, need: u64, total: u64) -> Option<String> {
    (need > total).then(|| {
        format!(
            "`granules` = {} on the `mesh` {} need at least {:.1} GB for the granules' own \
             buffers, more than this machine's {:.1} GB of memory: use fewer granules or a \
             coarser mesh",
            scene.granules,
            scene.mesh,
            need as f64 / 1e9,
            total as f64 / 1e9
        )
    })
}

/// Runs `scene` from `control`'s checkpoint, else its packing, else a
/// fresh pour, reporting to `observer`. Errors before the first step
/// (pour failed, bad setup, packing or checkpoint unfit) are returned; an
/// error while stepping ends the run and is kept in [`BedRun::error`].
pub fn run_bed(
    scene: &Scene,
    control: &RunControl,
    observer: &mut dyn BedObserver,
) -> anyhow::Result<BedRun> {
    let material = scene.material()?;
    let radius = scene.radius_m();
    let mesh = scene.granule_mesh()?;
    let mut params = assembly_params(scene, &mesh)?;
    check_feasible_on(
        scene,
        &mesh,
        &material,
        params.elements.points_per_element(),
    )?;
    // Where the run starts: a fresh pour, or a checkpoint's state.
    let (die, placed, resumed, pour_wall_time_s) = match &control.resume {
        Some(c) => {
            // Any placement: the checkpoint's state replaces it.
            let placed = vec![crate::assembly::Placement::at([0.0; 3]); scene.granules];
            (c.progress.die, placed, Some(c), c.progress.pour_wall_time_s)
        }
        None => {
            let poured;
            let packing = match &control.packing {
                Some(p) => p,
                None => {
                    poured = pour(scene, control.interrupt, &mut |s, t| observer.pour(s, t))?;
                    &poured
                }
            };
            if control.interrupt.is_some_and(|f| f.load(Ordering::SeqCst)) {
                return Err(anyhow::Error::new(crate::signal::Interrupted(
                    "interrupted before the compression's first step: there is nothing to \
                     resume (no checkpoint written)"
                        .to_owned(),
                )));
            }
            let die_radius = 0.5e-3 * scene.die_diameter_mm;
            if packing.centres.len() != scene.granules
                || packing.radius_m != radius
                || packing.die_radius_m != die_radius
            {
                anyhow::bail!(
                    "the packing ({} spheres of radius {} m in a die of radius {} m) does not fit \
                     the scene ({} granules of radius {radius} m, die radius {die_radius} m)",
                    packing.centres.len(),
                    packing.radius_m,
                    packing.die_radius_m,
                    scene.granules
                );
            }
            let die = DieScene::new(&packing.centres, radius, die_radius, scene.punch_speed_m_s);
            let placed = placements(&packing.centres, scene.seed);
            (die, placed, None, packing.wall_time_s)
        }
    };
    // The time at which the punch reaches the strain from which every
    // contact sweep searches (it starts at t = 0); never at 1 or more.
    params.exact_contact_from_s = if scene.exact_contact_from_strain < 1.0 {
        die.time_of_strain(scene.exact_contact_from_strain)
    } else {
        Real::INFINITY
    };
    let mut asm = Assembly::new(params, &mesh, &placed, die.walls())
        .map_err(anyhow::Error::new)
        .context("cannot set up the bed")?;
    if let Some(c) = resumed {
        asm.restore(&c.state)
            .map_err(anyhow::Error::new)
            .context("the checkpoint does not fit the scene")?;
        // A changed safety factor or mass scaling (--time-step-safety,
        // --mass-scaling with --resume) applies at once, not only from the
        // next re-estimate.
        let before = Scene::from_toml(&c.progress.scene_toml).context("the checkpoint's scene")?;
        if before.time_step_safety != scene.time_step_safety {
            asm.rescale_time_step(scene.time_step_safety / before.time_step_safety);
        }
        asm.rescale_masses_from(before.mass_scaling);
    }
    let area = core::f64::consts::PI * die.die_radius_m * die.die_radius_m;
    let granules = scene.granules;
    let eta0 = material.params.eta0;
    let solid_volume_m3 = granules as Real
        * eta0
        * surface_geometry(&mesh.positions, &mesh.quads).map_or(Real::NAN, |(_, v)| v);
    // The phase times and counters of earlier segments (a checkpoint
    // before format 7 has none: the figures then start at its step).
    let (counters_before, counters_from_step) = resumed.map_or((PhaseTimes::default(), 0), |c| {
        (c.progress.counters, c.progress.counters_from_step)
    });
    let d = 2.0 * radius;
    // Wall time of earlier segments of a resumed run.
    let wall_before = resumed.map_or(0.0, |c| c.progress.compression_wall_time_s);
    let start = Instant::now();
    let wall = || wall_before + start.elapsed().as_secs_f64();
    // A row of the window `w` that ends at `strain` with the punches at
    // `imposed` (pressing in, or the upper one withdrawing).
    let sample = |asm: &mut Assembly<'_>,
                  w: &Window,
                  previous: Option<&BedSample>,
                  strain: Real,
                  imposed: ImposedCompression| {
        let [rho, rho_solid, a_dv, a_d] = geometry(asm, &mesh, eta0, d);
        asm.elastic_energy();
        let avg = |x: Real| if w.time > 0.0 { x / w.time } else { 0.0 };
        BedSample {
            time_s: asm.time(),
            strain,
            mean_strain: interval_mean_strain(
                previous.map(|p| (p.strain, p.steps)),
                strain,
                asm.steps(),
            ),
            upper_force_n: avg(w.impulse[0]),
            lower_force_n: avg(w.impulse[1]),
            die_friction_z_n: avg(w.impulse[2]),
            die_normal_force_n: avg(w.die_normal),
            upper_pressure_pa: avg(w.impulse[0]) / area,
            lower_pressure_pa: avg(w.impulse[1]) / area,
            coordination: coordination_number(avg(w.pairs), granules).unwrap_or(Real::NAN),
            coordination_with_walls: coordination_number_with_walls(
                avg(w.pairs),
                avg(w.walls),
                granules,
            )
            .unwrap_or(Real::NAN),
            relative_density_mean: rho,
            relative_density_solid: rho_solid,
            heywood_dv: a_dv,
            heywood_d: a_d,
            min_jacobian: if w.time > 0.0 { w.min_j } else { 1.0 },
            min_gauss_jacobian: asm.worst_element().map_or(Real::NAN, |(_, w)| w.ratio),
            max_node_speed_m_s: w.max_speed,
            // A detection that fails (it only can on non-finite positions,
            // which stop the step before) is reported as NaN.
            penetration_m: asm.penetration().map_or(Real::NAN, |g| -g),
            steps: asm.steps(),
            energies: *asm.energies(),
            kinetic_relative_j: asm.kinetic_relative_to(&imposed),
        }
    };
    let mut snapshots: Vec<Real> = scene.snapshot_strains.clone();
    snapshots.sort_by(Real::total_cmp);
    snapshots.dedup();
    let (mut samples, mut window, mut next, mut snapshots_done) = match resumed {
        Some(c) => {
            let p = &c.progress;
            for s in &p.samples {
                observer.sample(s, 0.0);
            }
            (p.samples.clone(), p.window, p.next_output, p.snapshots_done)
        }
        None => {
            let first = sample(&mut asm, &Window::default(), None, 0.0, die.imposed_at(0.0));
            observer.sample(&first, 0.0);
            (vec![first], Window::new(), scene.output_strain_interval, 0)
        }
    };
    // The snapshots due before the first step: at C = 0, and on a resume
    // those a failed write left to do (the checkpoint is of the step they
    // belong to; the tables that need its contact forces, which a
    // checkpoint does not keep, cannot be written, and the run says so).
    let mut warnings = Vec::new();
    let strain_now = die.strain_at(asm.time());
    while let Some(&c) = snapshots
        .get(snapshots_done)
        .filter(|&&c| c <= 0.0 || (resumed.is_some() && strain_now + 1e-12 >= c))
    {
        let c = c.max(0.0);
        observer.snapshot(c, &asm, &mesh)?;
        if c > 0.0 {
            warnings.push(format!(
                "the snapshot at C = {c} was written on --resume, at the state of the step it \
                 belongs to but without its contacts, granules, network and stress tables \
                 (they need that step's contact forces, which a checkpoint does not keep)"
            ));
        }
        snapshots_done += 1;
    }
    let dir = control.checkpoint_dir.as_deref();
    // A fresh run leaves no withdrawal of an earlier run beside its own.
    if let Some(dir) = dir
        && control.resume.is_none()
    {
        remove_withdrawal_checkpoint(dir)?;
    }
    // The withdrawal of a finished run resumed without a step: its
    // checkpoints (rewritten for a changed scene) keep it.
    let kept = resumed
        .filter(|c| c.state.time >= die.time_of_strain(scene.final_strain))
        .filter(|c| withdrawal_holds(&c.progress.scene_toml, scene))
        .and_then(|c| c.progress.unloading.clone());
    let make =
        |asm: &Assembly<'_>, samples: &[BedSample], window: &Window, next: Real, done: usize| {
            Checkpoint {
                progress: checkpoint::Progress {
                    scene_toml: scene.to_toml(),
                    die,
                    pour_wall_time_s,
                    compression_wall_time_s: wall(),
                    samples: samples.to_vec(),
                    window: *window,
                    next_output: next,
                    snapshots_done: done,
                    counters: counters_before + asm.times(),
                    counters_from_step,
                    unloading: kept.clone(),
                    withdrawal: None,
                },
                state: asm.state(),
            }
        };
    // The state at the last output row, kept in memory so that a failed
    // step (which has already changed some granules) still leaves a
    // checkpoint from before it; and the steps and strain of the newest
    // checkpoint on disk.
    let mut last_good = dir.map(|_| make(&asm, &samples, &window, next, snapshots_done));
    let mut on_disk: Option<(u64, Real)> = None;
    let end = die.time_of_strain(scene.final_strain);
    let every_s = 60.0 * scene.checkpoint_interval_minutes;
    let mut last_checkpoint = Instant::now();
    let mut next_checkpoint_strain = die.strain_at(asm.time()) + scene.checkpoint_strain_interval;
    let mut error = None;
    let mut stopped = false;
    let mut interrupted = false;
    let resumed_past_end = resumed.is_some() && asm.time() >= end;
    let first_step = asm.steps();
    while asm.time() < end {
        if let Err(e) = asm.step() {
            error = Some(e);
            break;
        }
        window.add_step(&asm);
        let strain = die.strain_at(asm.time());
        // A snapshot that cannot be written (a full disk, say) ends the run
        // after this step's row and a checkpoint of it: the step itself
        // succeeded, and the run so far is kept for `--resume`, which
        // writes the snapshot again.
        let mut snapshot_failed = None;
        while snapshots
            .get(snapshots_done)
            .is_some_and(|&c| strain + 1e-12 >= c)
        {
            if let Err(e) = observer.snapshot(snapshots[snapshots_done], &asm, &mesh) {
                snapshot_failed = Some(e);
                break;
            }
            snapshots_done += 1;
        }
        if strain + 1e-12 >= next || asm.time() >= end {
            let imposed = die.imposed_at(asm.time());
            let s = sample(&mut asm, &window, samples.last(), strain, imposed);
            observer.sample(&s, wall());
            samples.push(s);
            window = Window::new();
            while next <= strain + 1e-12 {
                next += scene.output_strain_interval;
            }
            if dir.is_some() {
                // Drop the old copy first: one copy of the state at a time.
                drop(last_good.take());
                last_good = Some(make(&asm, &samples, &window, next, snapshots_done));
            }
        }
        let stop = control.stop_at_strain.is_some_and(|c| strain + 1e-12 >= c);
        let interrupt = control.interrupt.is_some_and(|f| f.load(Ordering::SeqCst));
        if stop
            || interrupt
            || snapshot_failed.is_some()
            || strain >= next_checkpoint_strain
            || last_checkpoint.elapsed().as_secs_f64() >= every_s
        {
            if let Some(dir) = dir {
                make(&asm, &samples, &window, next, snapshots_done).write(dir)?;
                on_disk = Some((asm.steps(), strain));
            }
            last_checkpoint = Instant::now();
            while next_checkpoint_strain <= strain {
                next_checkpoint_strain += scene.checkpoint_strain_interval;
            }
        }
        if let Some(e) = snapshot_failed {
            return Err(match dir {
                Some(dir) => anyhow::anyhow!(
                    "{e:#}; the run so far is kept in {}: `granbed-cli bed --resume {}` continues \
                     it",
                    dir.join(checkpoint::FILE_NAME).display(),
                    dir.display()
                ),
                None => e,
            });
        }
        if stop {
            stopped = true;
            break;
        }
        if interrupt {
            interrupted = true;
            break;
        }
    }
    // A run that reached its final strain ends with a checkpoint of its
    // last step, so that `--resume --strain` can take it further.
    if let Some(dir) = dir
        && error.is_none()
        && asm.time() >= end
        && asm.steps() > first_step
        && on_disk.is_none_or(|(steps, _)| steps < asm.steps())
    {
        make(&asm, &samples, &window, next, snapshots_done).write(dir)?;
        on_disk = Some((asm.steps(), die.strain_at(asm.time())));
    }
    // A resumed run that took no step but changed its scene (a finished
    // run refitted with --kawakita-min-strain, say) keeps the change: its
    // checkpoint is written again with the scene, else the next --resume
    // would go back to the old one.
    if let (Some(dir), Some(c)) = (dir, &control.resume)
        && error.is_none()
        && asm.steps() == first_step
        && on_disk.is_none()
        && c.progress.scene_toml != scene.to_toml()
    {
        make(&asm, &samples, &window, next, snapshots_done).write(dir)?;
        on_disk = Some((asm.steps(), die.strain_at(asm.time())));
    }
    let mut checkpoint_strain = on_disk.map(|(_, c)| c);
    if let (Some(_), Some(dir), Some(good)) = (&error, dir, &last_good) {
        let newer = on_disk.is_none_or(|(steps, _)| good.state.steps > steps);
        if newer {
            good.write(dir)?;
            checkpoint_strain = Some(die.strain_at(good.state.time));
        }
    }
    // A run that reached its final strain ends with a snapshot of its
    // final state, listed in `snapshot_strains` or not (a run past the
    // published list's 0.3 had no picture of its end); after its last
    // checkpoint, which a failure to write the snapshot must not cost. A
    // finished run resumed without a step has its end's snapshot already
    // (and a lower --strain would mislabel it: the state is at the old end).
    if error.is_none()
        && !stopped
        && !interrupted
        && !resumed_past_end
        && asm.time() >= end
        && !snapshots.iter().any(|&c| c >= scene.final_strain - 1e-12)
    {
        observer.snapshot(scene.final_strain, &asm, &mesh)?;
    }
    let wall_time_s = wall();
    let hidden_overlap =
        (control.check_final_overlap && error.is_none() && !interrupted).then(|| {
            let start = Instant::now();
            let deepest = asm.hidden_overlap();
            HiddenOverlap {
                deepest,
                wall_time_s: start.elapsed().as_secs_f64(),
            }
        });
    let final_granules = if error.is_none() {
        granules_at_end(&asm, &mesh, d)
    } else {
        Vec::new()
    };
    let steps = asm.steps();
    let strain_reached = die.strain_at(asm.time());
    let phase_times = counters_before + asm.times();
    // The withdrawal, after every figure of the loading is taken. A
    // finished run resumed without a step keeps its checkpoint's; else
    // the checkpoint of the loading's end is written again with it, so
    // that `--resume --strain` still continues the loading.
    let finished = error.is_none() && !stopped && !interrupted && asm.time() >= end;
    let added_mass = AddedMass::of(&asm);
    let unloading = match (finished && scene.unload, kept.clone(), samples.last()) {
        (true, Some(kept), _) => Some(kept),
        (true, None, Some(_)) => {
            // One copy of the state at a time: the loading's is done with.
            drop(last_good.take());
            let at_end_checkpoint =
                dir.map(|_| make(&asm, &samples, &window, next, snapshots_done));
            // A withdrawal an interrupt stopped goes on from its own
            // checkpoint if it turned at this very step of this very
            // loading (the die and every row to the bit) under a scene that
            // withdraws alike; any other is stale and goes.
            let resume = dir.and_then(|dir| {
                let c = checkpoint::Checkpoint::read_from(dir, checkpoint::WITHDRAWAL_FILE_NAME)
                    .ok()?;
                let w = c.progress.withdrawal?;
                (w.turn_steps == asm.steps()
                    && c.progress.die == die
                    && checkpoint::same_rows(&c.progress.samples, &samples)
                    && withdrawal_holds(&c.progress.scene_toml, scene))
                .then_some((w, c.state))
            });
            if let Some(dir) = dir
                && resume.is_none()
            {
                remove_withdrawal_checkpoint(dir)?;
            }
            // The withdrawal's checkpoint: the loading's end's progress
            // with the withdrawal's, and the state then.
            let save = dir.zip(at_end_checkpoint.as_ref()).map(|(dir, c)| {
                move |asm: &Assembly<'_>, w: checkpoint::WithdrawalProgress| {
                    Checkpoint {
                        progress: checkpoint::Progress {
                            withdrawal: Some(w),
                            ..c.progress.clone()
                        },
                        state: asm.state(),
                    }
                    .write_as(dir, checkpoint::WITHDRAWAL_FILE_NAME)
                    .map(|_| ())
                }
            });
            let u = withdraw(
                &mut asm,
                (&die, scene),
                &samples,
                (control.interrupt, observer),
                &sample,
                WithdrawalStore {
                    resume,
                    save: save.as_ref().map(|f| f as &SaveWithdrawal<'_>),
                    every_s,
                },
            )?;
            if let (Some(dir), Some(mut c)) = (dir, at_end_checkpoint)
                && u.cut_short.is_none()
            {
                c.progress.unloading = Some(u.clone());
                c.write(dir)?;
                remove_withdrawal_checkpoint(dir)?;
            }
            // Only a withdrawal the interrupt cut short counts: one that
            // completed in the step the signal came in is whole and kept.
            interrupted |= matches!(u.cut_short, Some(CutShort::Interrupted { .. }));
            Some(u)
        }
        _ => None,
    };
    Ok(BedRun {
        samples,
        bed_height_m: die.bed_height_m,
        die_radius_m: die.die_radius_m,
        granules: scene.granules,
        hexes_per_granule: mesh.hexes.len(),
        element_size_m: mesh.shortest_surface_edge(),
        steps,
        strain_reached,
        element_steps: steps * (scene.granules * mesh.hexes.len()) as u64,
        pour_wall_time_s,
        wall_time_s,
        phase_times,
        counters_from_step,
        solid_volume_m3,
        threads: rayon::current_num_threads(),
        stopped,
        interrupted,
        resumed_past_end,
        warnings,
        error,
        checkpoint_strain,
        rate_change_rel: None,
        half_speed_unloading: None,
        added_mass,
        hidden_overlap,
        final_granules,
        unloading,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The interval's mean strain is the Δt-weighted mean of C at the ends
    /// of its steps, as the forces are averaged: exact (to round-off) for
    /// equal steps, and within half a step's strain times the steps'
    /// relative spread when they differ.
    #[test]
    fn the_mean_strain_of_an_interval_is_that_of_its_steps() {
        let rate = 3.0; // strain per second
        let (t0, c0, from) = (0.02, 0.06, 500_u64);
        let brute = |dts: &[Real]| {
            let (mut t, mut sum) = (t0, 0.0);
            for &dt in dts {
                t += dt;
                sum += rate * t * dt;
            }
            let total: Real = dts.iter().sum();
            (sum / total, rate * t)
        };
        for n in [1_u64, 2, 7, 129] {
            let dts = vec![4e-6; n as usize];
            let (mean, c) = brute(&dts);
            let got = interval_mean_strain(Some((c0, from)), c, from + n);
            assert!((got - mean).abs() < 1e-14, "n = {n}: {got} against {mean}");
            assert!(got > c0 && got <= c);
        }
        // Steps growing by 10 % over the interval: off by Var(Δt)/(2⟨Δt⟩),
        // (0.1 ⟨Δt⟩)²/12/(2⟨Δt⟩) = 4.2·10⁻⁴ of a step.
        let n = 100;
        let dts: Vec<Real> = (0..n)
            .map(|k| 4e-6 * (1.0 + 0.1 * k as Real / 99.0))
            .collect();
        let (mean, c) = brute(&dts);
        let got = interval_mean_strain(Some((c0, from)), c, from + n as u64);
        let step = rate * 4.2e-6;
        assert!(
            (got - mean).abs() <= 5e-4 * step && (got - mean).abs() >= 3e-4 * step,
            "{got} against {mean}"
        );
        // The first row, and a row after no step, keep their own strain.
        assert_eq!(interval_mean_strain(None, 0.0, 0), 0.0);
        assert_eq!(interval_mean_strain(Some((c0, from)), c0, from), c0);
    }

    /// Every numerical field of a scene reaches the assembly: each set to a
    /// value the standard parameters (what an unwired field keeps) do not
    /// have, and found again (lengths as fractions of the element size).
    #[test]
    fn every_scene_field_reaches_the_assembly() {
        let standard = AssemblyParams::standard(
            Scene::published().material().unwrap(),
            Scene::published().element_settings().unwrap(),
        );
        assert!(!standard.selective_mass_scaling && !standard.contact.nearest_penetrated_face);
        let scene = Scene {
            granule_type: "C3".to_owned(),
            mesh: "4x1".to_owned(),
            element: "fbar".to_owned(),
            hourglass_kappa: 0.07,
            damping_ratio: 0.3,
            contact_sweeps: 7,
            sweep_tolerance: 0.02,
            exact_sweep_tolerance: Some(0.003),
            mass_scaling: 12.0,
            selective_mass_scaling: true,
            selective_mass_ratio: 4.0,
            time_step_safety: 0.6,
            time_step_floor: 0.4,
            max_mass_factor: 3.0,
            rigid_until_touched: false,
            local_sweeps: false,
            hold_constraints: true,
            contact_search_interval: 3,
            contact_capture: 0.07,
            held_reprojection: 0.2,
            nearest_penetrated_face: true,
            face_list_skin: 0.3,
            watchdog_speed_ratio: 50.0,
            watchdog_energy_ratio: 8.0,
            punch_speed_m_s: 0.02,
            ..Scene::published()
        };
        scene.validate().unwrap();
        let mesh = scene.granule_mesh().unwrap();
        let h = mesh.shortest_surface_edge();
        let p = assembly_params(&scene, &mesh).unwrap();
        assert_eq!(p.material, scene.material().unwrap());
        assert_eq!(p.elements, scene.element_settings().unwrap());
        assert_eq!(p.elements.hourglass_kappa, 0.07);
        assert_eq!(p.damping_ratio, 0.3);
        assert_eq!(p.contact_sweeps, 7);
        assert_eq!(p.sweep_tolerance_m, 0.02 * h);
        assert_eq!(p.exact_sweep_tolerance_m, 0.003 * h);
        assert_eq!(p.mass_scaling, 12.0);
        assert!(p.selective_mass_scaling);
        assert_eq!(p.selective_mass_ratio, 4.0);
        assert_eq!(p.time_step_safety, 0.6);
        assert_eq!(p.time_step_floor, 0.4);
        assert_eq!(p.max_mass_factor, 3.0);
        assert!(!p.rigid_until_touched && !p.local_sweeps && p.hold_constraints);
        assert_eq!(p.contact_search_interval, 3);
        assert_eq!(p.contact.capture, 0.07 * h);
        assert_eq!(p.contact.reproject_slide, 0.2 * h);
        assert!(p.contact.watch_beside);
        assert!(p.contact.nearest_penetrated_face);
        assert_eq!(p.face_list_skin, 0.3);
        assert_eq!(p.max_node_speed_m_s, 50.0 * 0.02);
        assert_eq!(p.kinetic_energy_limit, 8.0);
        // No re-projection, no watch.
        let never = Scene {
            held_reprojection: Real::INFINITY,
            ..scene
        };
        let p = assembly_params(&never, &mesh).unwrap();
        assert!(!p.contact.watch_beside && p.contact.reproject_slide.is_infinite());
    }

    /// The estimate before the pour is within a factor of two of the
    /// published scene's 7 723 steps (BENCHMARKS.md, sessions 37–54; the
    /// element estimate is the conservative one, so above), and a stiff,
    /// light material is refused by its fields.
    #[test]
    fn the_published_scene_is_estimated_and_a_runaway_material_refused() {
        let scene = Scene::published();
        let mesh = scene.granule_mesh().unwrap();
        let material = scene.material().unwrap();
        let steps = run_length(&scene, &mesh, &material).steps();
        assert!((7723.0..2.0 * 7723.0).contains(&steps), "{steps}");
        assert!(
            run_length(&scene, &mesh, &material)
                .refusal(MAX_STEPS, "f")
                .is_none()
        );
        let mut runaway = scene.clone();
        runaway.material.youngs_modulus_pa = Some(1e13);
        runaway.material.true_density_kg_m3 = Some(1e-3);
        // Elastic (σ_y ≥ 1e-6 E would be 10 MPa).
        runaway.material.yield_stress_pa = Some(f64::INFINITY);
        let material = runaway.material().unwrap();
        let e = run_length(&runaway, &mesh, &material)
            .refusal(MAX_STEPS, "the `[material]`")
            .expect("refused");
        assert!(e.contains("the `[material]` set them"), "{e}");
    }
}
