//! The stress through the compact, from its elements. At each snapshot
//! after a step, the die volume between the punches is cut into
//! [`LAYERS`] horizontal layers of equal height, and each layer gets the
//! volume average, over the whole layer, of its elements' axial stress
//! −σ_zz and lateral stress −(σ_xx + σ_yy)/2 (an element counts in the
//! layer of its centre; the room between the granules counts unstressed),
//! and its solid fraction. That is the powder's macroscopic stress, as a
//! load cell would read it: the mean axial stress of a layer is the mean
//! axial force across its horizontal planes over the die's area.
//!
//! Written as `vtk/stress_<k>.csv` ([`STRESS_COLUMNS`]: a row per layer,
//! bottom first, with the snapshot step's wall readings on every row),
//! and gathered from there into `summary.json`'s `stress_by_height`
//! ([`StressSummary`]) and the report, so that a finished run resumed
//! without a step keeps them.
//!
//! **What the walls say it must be.** For a body at rest without body
//! forces, ∫ σ dV = Σ x ⊗ f over the forces f on its boundary at points x
//! (the virial theorem; for the one-point element Σ_I x_I ⊗ f_I = V σ holds
//! element by element, and the granule pairs' forces act at the same point
//! on both granules, up to the contact gap, so they cancel). Two checks
//! follow, which the tests hold the bed to:
//! * **lateral**: the die wall pushes inwards at radius R_d, so the
//!   compact's mean lateral stress is R_d times the wall's normal force
//!   over twice the compact's volume, F_n/(2π R_d H): the die-wall
//!   pressure, read from the wall's forces alone (`die_wall_pa`). The
//!   walls' readings leave out the punches' faces' friction Σ r f_r on the
//!   granules under them, and the theorem at rest the bed's inertia, its
//!   damping and the hourglass forces: together they put the two apart by
//!   a few per cent (the published scene: +0.2, +1.8, +2.5 % at C = 0.1,
//!   0.2, 0.3; the tests' bed of 100 coarse granules +1.5 %, and −1.6 %
//!   with every friction coefficient 0, BENCHMARKS.md). The file's
//!   `walls_lateral_pa` is the theorem's figure from every wall force, the
//!   punches' faces' friction included: the published scene's elements are
//!   within 0.6 % of it (session 53);
//! * **axial**: the die wall's friction takes the axial force down from the
//!   upper punch's to the lower punch's on its way through the compact, so
//!   every layer's mean axial stress lies between P_lower and P_upper (up
//!   to the bed's weight over the die's area, `weight_pa`, which adds
//!   downwards).
//!
//! **Janssen.** With a constant ratio K of lateral to axial stress and the
//! wall's friction fully mobilised (μ), the axial stress falls with depth
//! as exp(−4μK d/D) (D the die's diameter): the lower punch would get
//! exp(−4μK H/D) of the upper one's pressure. [`StressSummary`] sets that
//! beside the punches' measured ratio.

use std::path::Path;

use granbed_kernel::Real;
use serde::Serialize;

use super::snapshots::ElementFields;
use crate::csv::{Field, read_table_or_older, write_table};

/// Layers of equal height the compact is cut into.
pub const LAYERS: usize = 10;

/// Columns of a stress file, in order: (name, meaning with its unit).
pub const STRESS_COLUMNS: [(&str, &str); 13] = [
    (
        "strain",
        "the snapshot's nominal axial strain C (the state is that of the step that first reached it)",
    ),
    (
        "bottom",
        "the layer's lower face, as a fraction of the compact's height H (0: the lower punch)",
    ),
    ("top", "the layer's upper face, as a fraction of H"),
    (
        "solid_fraction",
        "the solid volume of the elements whose centres lie in the layer (η0 V0 each) over the layer's volume π R_d² H/10",
    ),
    (
        "axial_stress_pa",
        "Σ −σ_zz v over the layer's elements (v each one's volume) over the layer's volume, Pa, positive in compression: the mean axial force across the layer over the die's area",
    ),
    (
        "lateral_stress_pa",
        "Σ −(σ_xx + σ_yy)/2 v over the layer's elements over the layer's volume, Pa, positive in compression: the layer's mean lateral stress",
    ),
    (
        "height_m",
        "the compact's height H between the punches at the snapshot, m",
    ),
    (
        "upper_punch_pa",
        "the upper punch's force in the snapshot's step over the die's area π R_d², Pa",
    ),
    (
        "lower_punch_pa",
        "the lower punch's force in the snapshot's step over the die's area, Pa",
    ),
    (
        "die_wall_pa",
        "the die wall's normal force F_n in the snapshot's step over its area beside the compact, F_n/(2π R_d H), Pa: by the virial theorem the compact's mean lateral stress",
    ),
    (
        "weight_pa",
        "the bed's weight (the granules' physical mass, without mass scaling, times g) over the die's area, Pa",
    ),
    (
        "walls_lateral_pa",
        "−Σ (x f_x + y f_y)/2 over every force f the walls (die and punches, friction included) put on the granules' nodes at x, over the compact's volume π R_d² H, Pa: by the virial theorem the compact's mean lateral stress at rest, the punches' faces' friction included (NaN in files written before the column existed)",
    ),
    (
        "walls_axial_pa",
        "−Σ z f_z over the same forces over π R_d² H, Pa: by the virial theorem the compact's mean axial stress at rest (the upper punch's share is its pressure times H/H, the die wall's friction the rest; NaN in older files)",
    ),
];

/// Columns of the stress files written before the walls' virials.
const COLUMNS_BEFORE_VIRIAL: usize = 11;

/// One layer of a profile.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StressLayer {
    /// Lower face, fraction of the compact's height.
    pub bottom: Real,
    /// Upper face, fraction of the compact's height.
    pub top: Real,
    /// Solid volume over the layer's volume.
    pub solid_fraction: Real,
    /// Mean axial stress −σ_zz over the layer, Pa (compression positive).
    pub axial_stress_pa: Real,
    /// Mean lateral stress −(σ_xx + σ_yy)/2 over the layer, Pa.
    pub lateral_stress_pa: Real,
}

/// What the walls read in a snapshot's step (the denominators and bounds
/// of the profile's checks).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WallReadings {
    /// The compact's height H between the punches, m.
    pub height_m: Real,
    /// Upper punch force / π R_d², Pa.
    pub upper_punch_pa: Real,
    /// Lower punch force / π R_d², Pa.
    pub lower_punch_pa: Real,
    /// Die-wall normal force / (2π R_d H), Pa.
    pub die_wall_pa: Real,
    /// The bed's weight / π R_d², Pa.
    pub weight_pa: Real,
    /// −Σ (x f_x + y f_y)/2 over the walls' forces on the nodes, over the
    /// compact's volume, Pa: the virial theorem's mean lateral stress.
    pub walls_lateral_pa: Real,
    /// −Σ z f_z over the walls' forces over the compact's volume, Pa: the
    /// virial theorem's mean axial stress.
    pub walls_axial_pa: Real,
}

/// The profile of one snapshot: what its file holds.
#[derive(Clone, Debug, PartialEq)]
pub struct StressProfile {
    /// The snapshot's index k.
    pub snapshot: usize,
    /// Its nominal axial strain.
    pub strain: Real,
    /// The walls in its step.
    pub walls: WallReadings,
    /// [`LAYERS`] layers, bottom first.
    pub layers: Vec<StressLayer>,
}

/// The profile of the elements `fields` (all granules' elements, with
/// their volumes and centres' heights) in a die of radius `die_radius_m`
/// whose punches are `walls.height_m` apart, the lower one at z = 0. An
/// element whose centre lies outside the compact (a contact's overlap at
/// a punch) counts in the nearest layer; an element with NaN fields makes
/// its layer's figures NaN.
pub fn stress_profile(
    snapshot: usize,
    strain: Real,
    fields: &ElementFields,
    die_radius_m: Real,
    walls: WallReadings,
) -> StressProfile {
    let height = walls.height_m;
    let sums = super::density_map::cell_sums(fields, die_radius_m, height, 1);
    let layer_volume =
        core::f64::consts::PI * die_radius_m * die_radius_m * height / LAYERS as Real;
    let layers = sums
        .iter()
        .enumerate()
        .map(|(l, s)| StressLayer {
            bottom: l as Real / LAYERS as Real,
            top: (l + 1) as Real / LAYERS as Real,
            solid_fraction: s[0] / layer_volume,
            axial_stress_pa: s[1] / layer_volume,
            lateral_stress_pa: s[2] / layer_volume,
        })
        .collect();
    StressProfile {
        snapshot,
        strain,
        walls,
        layers,
    }
}

impl StressProfile {
    /// The file's rows, one per layer.
    fn rows(&self) -> impl Iterator<Item = [Field; 13]> + '_ {
        let w = self.walls;
        self.layers.iter().map(move |l| {
            [
                self.strain,
                l.bottom,
                l.top,
                l.solid_fraction,
                l.axial_stress_pa,
                l.lateral_stress_pa,
                w.height_m,
                w.upper_punch_pa,
                w.lower_punch_pa,
                w.die_wall_pa,
                w.weight_pa,
                w.walls_lateral_pa,
                w.walls_axial_pa,
            ]
            .map(Field::from)
        })
    }

    /// The profile of snapshot `snapshot` from its file's [`LAYERS`] rows
    /// (the wall readings and strain are the first row's; every row
    /// repeats them).
    fn from_rows(snapshot: usize, rows: &[[Real; 13]; LAYERS]) -> Self {
        let first = &rows[0];
        Self {
            snapshot,
            strain: first[0],
            walls: WallReadings {
                height_m: first[6],
                upper_punch_pa: first[7],
                lower_punch_pa: first[8],
                die_wall_pa: first[9],
                weight_pa: first[10],
                walls_lateral_pa: first[11],
                walls_axial_pa: first[12],
            },
            layers: rows
                .iter()
                .map(|r| StressLayer {
                    bottom: r[1],
                    top: r[2],
                    solid_fraction: r[3],
                    axial_stress_pa: r[4],
                    lateral_stress_pa: r[5],
                })
                .collect(),
        }
    }

    /// The mean of `value` over the layers: over the compact, as the layers
    /// are of equal height.
    fn mean(&self, value: fn(&StressLayer) -> Real) -> Real {
        self.layers.iter().map(value).sum::<Real>() / self.layers.len() as Real
    }
}

/// File name of the stress profile of snapshot `k`.
pub fn stress_file(k: usize) -> String {
    format!("stress_{k}.csv")
}

/// Writes `profile` as `vtk_dir`/[`stress_file`]`(profile.snapshot)`.
pub fn write_profile(vtk_dir: &Path, profile: &StressProfile) -> anyhow::Result<()> {
    write_table(
        &vtk_dir.join(stress_file(profile.snapshot)),
        &STRESS_COLUMNS,
        profile.rows(),
    )
}

/// The figures of one snapshot's profile in `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StressSummary {
    /// The snapshot's index k (`vtk/stress_<k>.csv`).
    pub snapshot: usize,
    /// Its nominal axial strain.
    pub strain: Real,
    /// The walls in its step.
    pub walls: WallReadings,
    /// The compact's mean axial stress (the mean of the layers'), Pa.
    pub mean_axial_stress_pa: Real,
    /// The compact's mean lateral stress, Pa: by the virial theorem the
    /// die-wall pressure `walls.die_wall_pa`.
    pub mean_lateral_stress_pa: Real,
    /// K = mean lateral / mean axial stress, from the elements.
    pub lateral_to_axial: Real,
    /// P_lower / P_upper in the snapshot's step: the share of the load
    /// that reaches the lower punch.
    pub lower_to_upper: Real,
    /// Janssen's share exp(−4 μ K H/D) for the wall's friction μ, this K
    /// and the compact's aspect H/D (`None` without a material).
    pub janssen_lower_to_upper: Option<Real>,
    /// The layers, bottom first.
    pub layers: Vec<StressLayer>,
}

impl StressSummary {
    /// The figures of `profile` in a die of radius `die_radius_m` whose
    /// wall's friction coefficient is `mu`.
    pub fn of(profile: &StressProfile, die_radius_m: Real, mu: Option<Real>) -> Self {
        let axial = profile.mean(|l| l.axial_stress_pa);
        let lateral = profile.mean(|l| l.lateral_stress_pa);
        let k = lateral / axial;
        let w = profile.walls;
        Self {
            snapshot: profile.snapshot,
            strain: profile.strain,
            walls: w,
            mean_axial_stress_pa: axial,
            mean_lateral_stress_pa: lateral,
            lateral_to_axial: k,
            lower_to_upper: w.lower_punch_pa / w.upper_punch_pa,
            janssen_lower_to_upper: mu
                .map(|mu| (-4.0 * mu * k * w.height_m / (2.0 * die_radius_m)).exp()),
            layers: profile.layers.clone(),
        }
    }
}

/// The stress files in `vtk_dir`, in the order of k, each read (header
/// and [`LAYERS`] numeric rows checked), and why each file that could not
/// be read was left out (a damaged file must not cost the run's other
/// outputs).
pub fn read_all(vtk_dir: &Path) -> (Vec<StressProfile>, Vec<String>) {
    super::snapshots::read_snapshot_files(vtk_dir, "stress_", "stress_by_height", |k, path| {
        let rows: [[Real; 13]; LAYERS] =
            read_table_or_older(path, &STRESS_COLUMNS, COLUMNS_BEFORE_VIRIAL)?
                .try_into()
                .map_err(|_| anyhow::anyhow!("`{}`: not {LAYERS} rows", path.display()))?;
        Ok(StressProfile::from_rows(k, &rows))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walls(height_m: Real) -> WallReadings {
        WallReadings {
            height_m,
            upper_punch_pa: 2e4,
            lower_punch_pa: 1.5e4,
            die_wall_pa: 8e3,
            weight_pa: 10.0,
            walls_lateral_pa: 8.1e3,
            walls_axial_pa: 1.7e4,
        }
    }

    /// Elements of 1 mm³ at given heights with given stresses, relative
    /// density 0.5.
    fn fields(elements: &[(Real, Real, Real)]) -> ElementFields {
        let mut f = ElementFields::default();
        for &(z, axial, lateral) in elements {
            f.height_m.push(z);
            f.volume_m3.push(1e-9);
            f.relative_density.push(0.5);
            f.axial_stress_pa.push(axial);
            f.lateral_stress_pa.push(lateral);
        }
        f
    }

    /// Each element in the layer of its centre, averaged over the whole
    /// layer's volume; the compact's mean is the mean of the layers; an
    /// element below the lower punch or above the upper one counts in the
    /// nearest layer.
    #[test]
    fn elements_are_averaged_over_their_layers() {
        let (r, h) = (1e-3, 1e-3);
        // Layer volume π 10⁻⁶ · 10⁻³ / 10 m³.
        let layer = core::f64::consts::PI * 1e-10;
        let f = fields(&[
            (0.05e-3, 100.0, 10.0),
            (0.01e-3, 300.0, 30.0),
            (-0.01e-3, 200.0, 20.0),
            (0.95e-3, 50.0, 5.0),
            (1.2e-3, 50.0, 5.0),
            (0.55e-3, 70.0, 7.0),
        ]);
        let p = stress_profile(3, 0.2, &f, r, walls(h));
        assert_eq!((p.snapshot, p.strain, p.layers.len()), (3, 0.2, LAYERS));
        let close = |a: Real, b: Real| (a - b).abs() <= 1e-12 * b.abs();
        let bottom = p.layers[0];
        assert_eq!((bottom.bottom, bottom.top), (0.0, 0.1));
        assert!(close(bottom.axial_stress_pa, 600.0 * 1e-9 / layer));
        assert!(close(bottom.lateral_stress_pa, 60.0 * 1e-9 / layer));
        assert!(close(bottom.solid_fraction, 1.5e-9 / layer));
        assert!(close(p.layers[5].axial_stress_pa, 70.0 * 1e-9 / layer));
        assert!(close(p.layers[9].axial_stress_pa, 100.0 * 1e-9 / layer));
        assert_eq!(p.layers[3].axial_stress_pa, 0.0);
        let s = StressSummary::of(&p, r, Some(0.5));
        let total = core::f64::consts::PI * r * r * h;
        assert!(close(s.mean_axial_stress_pa, 770.0 * 1e-9 / total));
        assert!(close(s.mean_lateral_stress_pa, 77.0 * 1e-9 / total));
        assert!(close(s.lateral_to_axial, 0.1));
        assert_eq!(s.lower_to_upper, 0.75);
        // H/D = 1/2: exp(−4 · 0.5 · 0.1 · 0.5).
        assert!(close(s.janssen_lower_to_upper.unwrap(), (-0.1_f64).exp()));
        assert_eq!(StressSummary::of(&p, r, None).janssen_lower_to_upper, None);
        // A NaN element makes its layer NaN, the others stay.
        let nan = fields(&[(0.05e-3, Real::NAN, 1.0), (0.55e-3, 1.0, 1.0)]);
        let p = stress_profile(0, 0.1, &nan, r, walls(h));
        assert!(p.layers[0].axial_stress_pa.is_nan() && p.layers[5].axial_stress_pa > 0.0);
    }

    /// The layers are those of a loop written out here, independent of
    /// the binning the density map shares: each element in the layer
    /// floor(10 z/H) (clamped), its volume-weighted values summed in
    /// element order and divided by the layer's volume, bit for bit, on
    /// elements spread over and beyond the compact.
    #[test]
    fn the_layers_are_those_of_a_plain_loop() {
        let (r, h) = (2e-3, 1.5e-3);
        // A fixed pseudo-random sequence in [0, 1).
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as Real / (1u64 << 53) as Real
        };
        let mut f = ElementFields::default();
        for _ in 0..500 {
            f.height_m.push(h * (1.2 * next() - 0.1));
            f.volume_m3.push(1e-12 * (0.5 + next()));
            f.relative_density.push(0.4 + 0.5 * next());
            f.axial_stress_pa.push(1e4 * (next() - 0.2));
            f.lateral_stress_pa.push(5e3 * next());
        }
        let mut sums = [[0.0; 3]; LAYERS];
        for e in 0..f.volume_m3.len() {
            let at = (f.height_m[e] / h * LAYERS as Real).floor();
            let l = if at < 0.0 {
                0
            } else {
                (at as usize).min(LAYERS - 1)
            };
            let v = f.volume_m3[e];
            sums[l][0] += v * f.relative_density[e];
            sums[l][1] += v * f.axial_stress_pa[e];
            sums[l][2] += v * f.lateral_stress_pa[e];
        }
        let layer = core::f64::consts::PI * r * r * h / LAYERS as Real;
        let p = stress_profile(1, 0.2, &f, r, walls(h));
        for (l, (got, want)) in p.layers.iter().zip(&sums).enumerate() {
            assert_eq!(got.solid_fraction, want[0] / layer, "layer {l}");
            assert_eq!(got.axial_stress_pa, want[1] / layer, "layer {l}");
            assert_eq!(got.lateral_stress_pa, want[2] / layer, "layer {l}");
        }
        assert!(sums.iter().all(|s| s[0] > 0.0));
    }

    /// A profile written reads back to the same bits; a file with a row
    /// missing is left out, and said so; the others are read.
    #[test]
    fn a_stress_file_round_trips() {
        let dir = std::env::temp_dir().join(format!("granbed-stress-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = fields(&[(0.15e-3, 1.0 / 3.0, 0.1), (0.75e-3, 2e3, 1e3)]);
        let a = stress_profile(2, 0.1 + 0.2, &f, 2e-3, walls(1e-3));
        let b = stress_profile(10, 0.3, &f, 2e-3, walls(0.9e-3));
        write_profile(&dir, &a).unwrap();
        write_profile(&dir, &b).unwrap();
        let (back, left_out) = read_all(&dir);
        assert!(left_out.is_empty(), "{left_out:?}");
        assert_eq!(back, [a.clone(), b]);
        let text = std::fs::read_to_string(dir.join(stress_file(2))).unwrap();
        let cut: String = text
            .lines()
            .take(LAYERS)
            .map(|l| format!("{l}\n"))
            .collect();
        std::fs::write(dir.join(stress_file(4)), cut).unwrap();
        let (back, left_out) = read_all(&dir);
        assert_eq!(back.iter().map(|p| p.snapshot).collect::<Vec<_>>(), [2, 10]);
        assert!(
            left_out.len() == 1
                && left_out[0].contains("stress_4.csv")
                && left_out[0].contains("rows"),
            "{left_out:?}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
