//! What `granbed-cli bed` writes: `compression.csv`, `summary.json` (then
//! the plots and `report.html`), the one-line summary, and the progress bar
//! on stderr.

use std::path::Path;

use crate::material_args::MaterialSummary;
use granbed_kernel::Real;
use granbed_kernel::analysis::bed::{heckel_fit, heckel_usable};
use granbed_kernel::analysis::quasi_static::LoadSample;
use indicatif::ProgressBar;
use serde::Serialize;

use super::density_map::MapSummary;
use super::network::NetworkStats;
use super::run::{BedRun, BedSample, GranuleAtEnd};
use super::scene::Scene;
use super::stress_profile::StressSummary;
use super::unloading::{UNLOADING_CSV, UnloadingSummary};
use crate::csv::{Field, write_table};
use crate::output::{finite_ratio, write_json};
use crate::progress::{StrainBar, draw_target, steps_per_second};
use crate::quasi_static::QuasiStatic;

/// Columns of `compression.csv`, in order: (name, meaning with its unit).
/// The report's glossary ([`super::report`]) shows the meanings.
pub const COMPRESSION_COLUMNS: [(&str, &str); 32] = [
    ("time_s", "time since the compression began, s"),
    (
        "strain",
        "axial strain C = (H0 − H)/H0 at the row, where the instantaneous columns were taken",
    ),
    (
        "mean_strain",
        "the output interval's mean axial strain: the strain the averaged columns (forces, pressures, Z) belong to, and the Kawakita and Heckel fits' C",
    ),
    (
        "upper_pressure_pa",
        "upper-punch pressure F/(π R_d²), Pa (averaged over the output interval, as every force)",
    ),
    ("lower_pressure_pa", "lower-punch pressure, Pa"),
    ("upper_force_n", "upper-punch force, N"),
    ("lower_force_n", "lower-punch force, N"),
    (
        "die_friction_z_n",
        "axial friction force of the die wall on the granules, N (positive upwards)",
    ),
    (
        "die_normal_force_n",
        "Σ normal (radial) force of the die wall on the granules, N (NaN: not recorded: the rows a checkpoint older than version 9 held, and the one in progress then)",
    ),
    (
        "die_wall_pressure_pa",
        "radial pressure on the die wall beside the compact, die_normal_force_n/(2π R_d H) with H the compact's height at the mean strain, Pa (NaN where the force is)",
    ),
    (
        "coordination",
        "coordination number Z = 2 N_pp/N: granule pairs in contact per granule (interval average)",
    ),
    (
        "coordination_with_walls",
        "(2 N_pp + N_pw)/N: Z with the granule–wall contacts counted too",
    ),
    (
        "relative_density_mean",
        "mean over the granules of their own relative density η0 V0/V",
    ),
    (
        "relative_density_solid",
        "the granules' total solid volume / their total volume",
    ),
    (
        "bed_solid_fraction",
        "the bed's solid fraction D: the granules' solid volume / the die volume below the upper punch",
    ),
    (
        "heywood_dv",
        "mean Heywood coefficient d_V S/V, d_V the volume-equivalent diameter (6 for a sphere)",
    ),
    ("heywood_d", "mean d S/V with the nominal diameter d"),
    (
        "min_jacobian",
        "smallest element Jacobian ratio at the element centres in the interval",
    ),
    (
        "min_gauss_jacobian",
        "smallest Gauss-point Jacobian ratio at the row (≤ 0: an element folded)",
    ),
    (
        "max_node_speed_m_s",
        "largest node speed in the interval, m/s",
    ),
    (
        "penetration_m",
        "deepest granule–granule overlap the contact detection reads at the row, m",
    ),
    ("steps", "time steps so far"),
    (
        "punch_work_j",
        "work of the moving punch on the bed so far, J",
    ),
    (
        "internal_work_j",
        "work of the internal and hourglass forces, J (≈ elastic + plastic + hourglass; the rest is the return map's energy gap)",
    ),
    ("elastic_j", "elastic energy Ψ stored in the granules, J"),
    ("plastic_j", "plastic dissipation, J"),
    (
        "hourglass_j",
        "energy in the one-point element's hourglass modes (spurious), J",
    ),
    ("damping_j", "energy removed by the damping, J"),
    ("kinetic_j", "kinetic energy, J"),
    (
        "kinetic_relative_j",
        "kinetic energy relative to the imposed compression: each granule's translation \
         counted against the compression's velocity at its centre, ½M(u − a)² in place of \
         ½Mu² (so above kinetic_j where granules lag it, as at rest at C = 0), J",
    ),
    (
        "contact_loss_j",
        "energy the contacts took out of the punch work (friction and the kinematic constraints), J",
    ),
    (
        "energy_residual_j",
        "energy-ledger residual ΔK + internal work + damping − contact work − gravity work, J (round-off)",
    ),
];

/// The granules' packing fraction of a row at `strain` (its own, or its
/// interval's mean strain for an averaged quantity): their envelope volume
/// over the die volume below the upper punch, D / (Σ solid / Σ V) — the
/// solid fraction D without the pores inside the granules, the fraction
/// Arzt's coordination law and the pour's packing fraction are written in
/// (not finite if the granules' volumes are not, which `summary.json`
/// writes as null). The granules' own density is the row's: it changes far
/// more slowly than D.
pub fn packing_fraction(run: &BedRun, s: &BedSample, strain: Real) -> Real {
    bed_solid_fraction(run, strain) / s.relative_density_solid
}

/// The radial pressure on the die wall of a row, Pa: its die-wall normal
/// force (an interval average) over the wall beside the compact, 2π R_d H
/// with H = H0 (1 − C) at the interval's mean strain. The granules touch
/// the wall at points, so this is the wall's mean pressure, the radial
/// stress σ_r of a continuum reading of the compact (NaN where the force
/// was not recorded).
pub fn die_wall_pressure(run: &BedRun, s: &BedSample) -> Real {
    let height = run.bed_height_m * (1.0 - s.mean_strain);
    s.die_normal_force_n / (2.0 * core::f64::consts::PI * run.die_radius_m * height)
}

/// The die wall's share of the load at one row ([`DieWallSummary`]).
pub fn die_wall_summary(run: &BedRun, s: &BedSample) -> DieWallSummary {
    let pressure_pa = die_wall_pressure(run, s);
    let ratio = |x: Real, y: Real| (y > 0.0).then(|| x / y).filter(|r| r.is_finite());
    DieWallSummary {
        mean_strain: s.mean_strain,
        pressure_pa: pressure_pa.is_finite().then_some(pressure_pa),
        mean_punch_pressure_pa: Some(mean_punch_pressure(s)).filter(|p| p.is_finite()),
        radial_to_axial: ratio(pressure_pa, mean_punch_pressure(s)),
        radial_to_upper: ratio(pressure_pa, s.upper_pressure_pa),
        friction_to_normal: ratio(s.die_friction_z_n.abs(), s.die_normal_force_n),
    }
}

/// The die wall's share of the load at an output row (`summary.json`'s
/// `final_die_wall`: the last row). `None` where a figure is not
/// recorded or its divisor is not positive.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DieWallSummary {
    /// The row's mean strain, to which its averaged forces belong.
    pub mean_strain: Real,
    /// Radial pressure on the die wall, Pa ([`die_wall_pressure`]).
    pub pressure_pa: Option<Real>,
    /// The mean of the two punches' pressures, Pa ([`mean_punch_pressure`]):
    /// the compact's axial stress averaged over its height, the divisor of
    /// `radial_to_axial`.
    pub mean_punch_pressure_pa: Option<Real>,
    /// That pressure over the mean of the two punches' pressures: the
    /// compact's radial-to-axial stress ratio, as an instrumented die
    /// measures it (Janssen's K).
    pub radial_to_axial: Option<Real>,
    /// The die-wall pressure over the upper punch's alone, the divisor
    /// instrumented-die studies often use (their σ_r read at one sensor).
    pub radial_to_upper: Option<Real>,
    /// |axial die friction| / die normal force: the wall's mobilised
    /// friction. Coulomb's law bounds it by the friction coefficient μ,
    /// which it reaches when every granule at the wall slides axially.
    pub friction_to_normal: Option<Real>,
}

/// The compact's height where the run ended, H0 (1 − C), m.
pub fn final_height_m(run: &BedRun) -> Real {
    run.bed_height_m * (1.0 - run.strain_reached)
}

/// The bed's solid fraction D at strain C: the granules' solid volume over
/// the die volume between the punches, `solid_volume_m3` /
/// (π R_d² H0 (1 − C)) — the relative density of the compact, whose
/// ln(1/(1 − D)) against the punch pressure is the Heckel plot.
pub fn bed_solid_fraction(run: &BedRun, strain: Real) -> Real {
    let die_area = core::f64::consts::PI * run.die_radius_m * run.die_radius_m;
    run.solid_volume_m3 / (die_area * run.bed_height_m * (1.0 - strain))
}

fn row(s: &BedSample, run: &BedRun) -> [Field; 32] {
    let e = &s.energies;
    [
        s.time_s.into(),
        s.strain.into(),
        s.mean_strain.into(),
        s.upper_pressure_pa.into(),
        s.lower_pressure_pa.into(),
        s.upper_force_n.into(),
        s.lower_force_n.into(),
        s.die_friction_z_n.into(),
        s.die_normal_force_n.into(),
        die_wall_pressure(run, s).into(),
        s.coordination.into(),
        s.coordination_with_walls.into(),
        s.relative_density_mean.into(),
        s.relative_density_solid.into(),
        bed_solid_fraction(run, s.strain).into(),
        s.heywood_dv.into(),
        s.heywood_d.into(),
        s.min_jacobian.into(),
        s.min_gauss_jacobian.into(),
        s.max_node_speed_m_s.into(),
        s.penetration_m.into(),
        Field::Int(s.steps),
        e.punch_work.into(),
        e.internal_work.into(),
        e.elastic.into(),
        e.plastic.into(),
        e.hourglass.into(),
        e.damping.into(),
        e.kinetic.into(),
        s.kinetic_relative_j.into(),
        e.contact_loss().into(),
        e.residual().into(),
    ]
}

/// `format` of a bed run's `summary.json`, as the granule's and the pour's
/// summaries name theirs.
pub const FORMAT: &str = "granbed-bed-summary";
/// Version of the bed's `summary.json` format; bumped when a field changes
/// meaning or disappears (adding a field does not bump it). 1: the format
/// as it was when these two fields were added (session 55).
pub const FORMAT_VERSION: u32 = 1;

/// The Kawakita fit of `summary.json`.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct KawakitaSummary {
    /// a (dimensionless).
    pub a: Option<Real>,
    /// 1/b, Pa.
    pub inv_b_pa: Option<Real>,
    /// R² of the fit.
    pub r_squared: Option<Real>,
    /// Points used: the output rows with C ≥ `min_strain`, C the row's
    /// mean strain ([`BedSample::mean_strain`]).
    pub points: usize,
    /// The fit's strain window starts here (the run's fit: scene
    /// `kawakita_min_strain`; `kawakita_windows`: each window's start).
    pub min_strain: Real,
}

/// A Heckel fit of `summary.json`: ln(1/(1 − D)) = K·P + A over the
/// output rows with C ≥ `min_strain`, D the bed's solid fraction
/// ([`bed_solid_fraction`]) and P the upper-punch pressure (`heckel`) or
/// the mean of the two punches' (`heckel_mean_pressure`), C and D at each
/// row's mean strain ([`heckel_rows`]).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct HeckelSummary {
    /// Mean yield pressure P_y = 1/K, Pa.
    pub yield_pressure_pa: Option<Real>,
    /// K, 1/Pa.
    pub k_per_pa: Option<Real>,
    /// A (dimensionless).
    pub a: Option<Real>,
    /// D_A = 1 − e^(−A).
    pub d_a: Option<Real>,
    /// D_B = D_A − D0, D0 the bed's solid fraction before the first step
    /// (`initial_solid_fraction`): Heckel's densification by the granules'
    /// rearrangement, the part of D_A the fit's line does not account for
    /// by plastic flow.
    pub d_b: Option<Real>,
    /// R² of the fit.
    pub r_squared: Option<Real>,
    /// Points used: the output rows with C ≥ `min_strain`, P finite and
    /// 0 < D < 1.
    pub points: usize,
    /// The fit's strain window starts here (the run's fits: scene
    /// `heckel_min_strain`; `heckel_windows`: each window's start).
    pub min_strain: Real,
}

impl HeckelSummary {
    /// Whether its ln(1/(1 − D)) is linear enough in P for P_y to be a
    /// material figure ([`fit_linear`]; no fit is not).
    pub fn linear(&self) -> bool {
        self.r_squared.is_some_and(fit_linear)
    }
}

/// The quasi-static certificate of a bed run: the upper punch drives, the
/// lower punch and the die-wall friction take up.
pub fn quasi_static(samples: &[BedSample], rate_change_rel: Option<Real>) -> QuasiStatic {
    let loads: Vec<LoadSample> = samples
        .iter()
        .map(|s| LoadSample {
            kinetic_j: s.energies.kinetic,
            internal_work_j: s.energies.internal_work,
            force_in_n: s.upper_force_n,
            force_out_n: Some(s.lower_force_n + s.die_friction_z_n),
            // NaN: not recorded (a sample of a checkpoint before format 5).
            kinetic_relative_j: (!s.kinetic_relative_j.is_nan()).then_some(s.kinetic_relative_j),
        })
        .collect();
    crate::quasi_static::judge(&loads, rate_change_rel)
}

/// The fields of `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary<'a> {
    /// Always [`FORMAT`].
    pub format: &'static str,
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// granbed version.
    pub version: &'static str,
    /// The scene as run. (JSON has no infinity: a field set to ∞ reads
    /// `null` here; `scene_toml` keeps it.)
    pub scene: &'a Scene,
    /// The scene as run, exactly, as a scene file's text (`--scene`
    /// reads it back; ∞ is `inf`).
    pub scene_toml: String,
    /// Kawakita a.
    pub kawakita_a: Option<Real>,
    /// Kawakita 1/b, Pa.
    pub kawakita_inv_b_pa: Option<Real>,
    /// The fit in full.
    pub kawakita: KawakitaSummary,
    /// The Heckel fit's mean yield pressure P_y, Pa.
    pub heckel_yield_pressure_pa: Option<Real>,
    /// The Heckel fit in full.
    pub heckel: HeckelSummary,
    /// The Kawakita fit again over each window of [`FIT_WINDOWS`]
    /// (C ≥ each; no figures for a window past the strain reached): how
    /// much a and 1/b depend on the window.
    pub kawakita_windows: Vec<KawakitaSummary>,
    /// The Heckel fit (upper-punch pressure) again over each window of
    /// [`FIT_WINDOWS`].
    pub heckel_windows: Vec<HeckelSummary>,
    /// The Heckel fit over the same rows on the mean of the two punches'
    /// pressures ([`mean_punch_pressure`]) instead of the upper one's.
    pub heckel_mean_pressure: HeckelSummary,
    /// The bed's solid fraction D0 at C = 0 (the poured bed: the granules'
    /// solid volume over the die volume below H0).
    pub initial_solid_fraction: Real,
    /// The bed's solid fraction D at the final strain (in the die, under
    /// load: D0/(1 − C)).
    pub final_solid_fraction: Real,
    /// The granules' packing fraction at C = 0 ([`packing_fraction`]:
    /// their envelope volume / the die volume below H0).
    pub initial_packing_fraction: Real,
    /// The granules' packing fraction at the end. As fractions of the die
    /// volume, 1 − it is the room between the granules and it × (1 − the
    /// granules' Σsolid/ΣV) the pores inside them; the two add up to
    /// 1 − D.
    pub final_packing_fraction: Real,
    /// The strains the quasi-static certificate judged: the first and the
    /// last of the second half of the output rows (`None`: no row).
    pub quasi_static_strains: Option<[Real; 2]>,
    /// The granules' mean relative density in each of [`DENSITY_LAYERS`]
    /// layers of the compact where the run ended, bottom first (empty for a
    /// run stopped by an error).
    pub final_density_by_height: Vec<DensityLayer>,
    /// The die wall's share of the load at the last row.
    pub final_die_wall: DieWallSummary,
    /// The contact network at each snapshot after a step, in strain order
    /// (`vtk/network_<k>.csv`, [`super::network`]): read from those files
    /// by [`write_all`], so a finished run resumed without a step keeps
    /// them; empty in a summary made without the files.
    pub contact_network: Vec<NetworkStats>,
    /// The stress through the compact at each snapshot after a step, in
    /// strain order (`vtk/stress_<k>.csv`, [`super::stress_profile`]):
    /// read from those files by [`write_all`], like `contact_network`.
    pub stress_by_height: Vec<StressSummary>,
    /// The density and stress in the compact's radial × height section at
    /// the last snapshot (`vtk/density_map_<k>.csv`,
    /// [`super::density_map`]): read from that file by [`write_all`], like
    /// `contact_network`; `None` without one or with a NaN cell.
    pub final_density_map: Option<MapSummary>,
    /// The upper punch's withdrawal after the final strain (scene
    /// `unload`; `None` without one): elastic recovery, residual die-wall
    /// pressure, the work of the cycle.
    pub unloading: Option<UnloadingSummary>,
    /// The granule material, every parameter (`None` if the scene's is
    /// invalid).
    pub material: Option<MaterialSummary>,
    /// Yield stress of the granules as run (the type's, or the scene's
    /// override), Pa.
    pub yield_stress_pa: Real,
    /// Initial relative density η0 of the granules as run.
    pub eta0: Real,
    /// Strain reached.
    pub final_strain: Real,
    /// Upper-punch pressure of the last sample, Pa.
    pub final_pressure_pa: Real,
    /// Mean granule relative density η0 V0/V of the last sample.
    pub final_relative_density: Real,
    /// Coordination number (granule pairs) of the last sample.
    pub final_coordination: Real,
    /// Largest upper-punch pressure of the samples, Pa.
    pub max_pressure_pa: Real,
    /// H0, m.
    pub initial_bed_height_m: Real,
    /// Granules.
    pub granules: usize,
    /// Hexes in the bed.
    pub elements: usize,
    /// Steps.
    pub steps: u64,
    /// Element evaluations.
    pub element_steps: u64,
    /// Wall time of the compression, s.
    pub wall_time_s: f64,
    /// Wall time of the pour, s.
    pub pour_wall_time_s: f64,
    /// Compression wall time per element evaluation, ns.
    pub ns_per_element_step: Option<f64>,
    /// Share of the contact phase in the compression's wall time (over
    /// the steps `cost_figures_from_step` on, as the figures below).
    pub contact_share: Option<f64>,
    /// Contact sweeps per step.
    pub contact_sweeps_per_step: Option<f64>,
    /// Face-list builds per step (a pair's two passes count one).
    pub face_list_builds_per_step: Option<f64>,
    /// Face-list anchor renewals per step, over all granules.
    pub anchor_renewals_per_step: Option<f64>,
    /// Pair searches (detections) per step, over all sweeps.
    pub pair_searches_per_step: Option<f64>,
    /// Share of the granule-steps taken as rigid bodies, without element
    /// work.
    pub rigid_granule_step_share: Option<f64>,
    /// The first step the cost figures above cover: 0 (the whole run,
    /// every resumed segment included) unless the run was resumed from a
    /// checkpoint older than format 7, which did not carry the counters
    /// (then that checkpoint's step; `warnings` says so).
    pub cost_figures_from_step: u64,
    /// Threads used.
    pub threads: usize,
    /// Smallest element Jacobian ratio (element centres, every step).
    pub min_jacobian: Real,
    /// Smallest Gauss-point Jacobian ratio at the output rows (≤ 0: an
    /// element folded).
    pub min_gauss_jacobian: Real,
    /// Largest nodal speed over the run / punch speed.
    pub max_node_speed_ratio: Option<Real>,
    /// Deepest granule–granule overlap at the output rows, m.
    pub max_penetration_m: Real,
    /// That overlap / the shortest surface edge of the reference mesh
    /// (the contact tolerance is 1 % of it).
    pub max_penetration_rel_element: Option<Real>,
    /// The overlap measured by geometry at the end of the run (the check of
    /// the contact detection that `max_penetration_*` reports, sharing none
    /// of its choices); null if not measured (a run stopped by an error or
    /// an interrupt).
    pub final_hidden_overlap: Option<HiddenOverlapSummary>,
    /// Hourglass energy / internal work at the end.
    pub hourglass_to_internal: Option<Real>,
    /// |ledger residual| / punch work.
    pub energy_residual_rel: Option<Real>,
    /// Contact losses / punch work.
    pub contact_loss_rel: Option<Real>,
    /// Peak resident memory of the process, bytes (Linux VmHWM).
    pub peak_memory_bytes: Option<u64>,
    /// The quasi-static certificate.
    pub quasi_static: QuasiStatic,
    /// What variable mass scaling did (scene `time_step_floor`).
    pub added_mass: super::run::AddedMass,
    /// True if SIGINT/SIGTERM stopped the run (after a step, with a
    /// checkpoint): `granbed-cli bed --resume DIR` continues it.
    pub interrupted: bool,
    /// What a reader of these figures must know (also printed on stderr):
    /// a final strain past the target, overlaps above 1 % of the element,
    /// a Kawakita fit outside the law's regime, cost figures over part of
    /// the run, scene fields left at pre-publication values, an
    /// interruption, a bed poured less than [`SHALLOW_BED_DIAMETERS`]
    /// granule diameters deep.
    pub warnings: Vec<String>,
    /// The error that stopped the run early, if any.
    pub error: Option<String>,
}

/// Peak resident set size of this process (Linux `/proc/self/status`
/// VmHWM), bytes.
pub fn peak_memory_bytes() -> Option<u64> {
    crate::output::proc_kib_field("/proc/self/status", "VmHWM:")
}

/// The Kawakita fit of the samples with C ≥ `min_strain`, each pressure
/// with its interval's mean strain ([`BedSample::mean_strain`]).
pub fn kawakita(samples: &[BedSample], min_strain: Real) -> KawakitaSummary {
    let points = samples.iter().map(|s| (s.upper_pressure_pa, s.mean_strain));
    let fit = granbed_kernel::analysis::bed::kawakita_fit(points, min_strain);
    KawakitaSummary {
        a: fit.map(|f| f.a),
        inv_b_pa: fit.map(|f| f.inv_b_pa),
        r_squared: fit.map(|f| f.r_squared),
        points: fit.map_or_else(
            || {
                samples
                    .iter()
                    .filter(|s| {
                        s.mean_strain >= min_strain
                            && s.mean_strain > 0.0
                            && s.upper_pressure_pa.is_finite()
                    })
                    .count()
            },
            |f| f.points,
        ),
        min_strain,
    }
}

/// The upper-punch pressure of a row, Pa: the pressure of the Heckel and
/// Kawakita fits.
pub fn upper_pressure(s: &BedSample) -> Real {
    s.upper_pressure_pa
}

/// The mean of the two punches' pressures of a row, Pa: about the
/// compact's mean axial pressure, which the die wall's friction lowers
/// from the upper punch down to the lower one (the upper punch's load is
/// the lower one's plus what the wall holds); the Heckel variant on it is
/// common in the literature.
pub fn mean_punch_pressure(s: &BedSample) -> Real {
    0.5 * (s.upper_pressure_pa + s.lower_pressure_pa)
}

/// The rows of a Heckel plot: (P in Pa, D, C) of every output row, with P
/// the row's `pressure` ([`upper_pressure`] or [`mean_punch_pressure`])
/// and C its interval's mean strain, the strain of the averaged P, at
/// which D is taken.
pub fn heckel_rows(
    run: &BedRun,
    pressure: fn(&BedSample) -> Real,
) -> impl Iterator<Item = (Real, Real, Real)> + Clone + '_ {
    run.samples.iter().map(move |s| {
        (
            pressure(s),
            bed_solid_fraction(run, s.mean_strain),
            s.mean_strain,
        )
    })
}

/// The Heckel fit of the run's output rows with C ≥ `min_strain`, on the
/// punch `pressure` of [`heckel_rows`].
pub fn heckel(run: &BedRun, min_strain: Real, pressure: fn(&BedSample) -> Real) -> HeckelSummary {
    let window = heckel_rows(run, pressure)
        .filter(move |&(_, _, c)| c >= min_strain)
        .map(|(p, d, _)| (p, d));
    let fit = heckel_fit(window.clone());
    HeckelSummary {
        yield_pressure_pa: fit.map(|f| f.yield_pressure_pa),
        k_per_pa: fit.map(|f| f.k_per_pa),
        a: fit.map(|f| f.a),
        d_a: fit.map(|f| f.d_a),
        d_b: fit.map(|f| f.d_a - bed_solid_fraction(run, 0.0)),
        r_squared: fit.map(|f| f.r_squared),
        points: fit.map_or_else(
            || window.filter(|&(p, d)| heckel_usable(p, d)).count(),
            |f| f.points,
        ),
        min_strain,
    }
}

/// The starts of the strain windows over which `summary.json`'s
/// `kawakita_windows` and `heckel_windows` fit the laws again: their
/// figures depend on the window (physics.md's C ≥ 0.25 is the published
/// one), and a reader should see by how much.
pub const FIT_WINDOWS: [Real; 4] = [0.10, 0.15, 0.20, 0.25];

/// Layers of equal height in which `summary.json` averages the granules'
/// relative density at the end ([`density_by_height`]).
pub const DENSITY_LAYERS: usize = 5;

/// One layer of the compact where the run ended.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DensityLayer {
    /// Its bottom, a fraction of the compact's height H = H0 (1 − C).
    pub from_height: Real,
    /// Its top, the same way.
    pub to_height: Real,
    /// Granules whose centre of mass lies in it.
    pub granules: usize,
    /// Their mean relative density η0 V0/V (`None` if there are none).
    pub mean_relative_density: Option<Real>,
}

/// The mean relative density of the `granules` in each of
/// [`DENSITY_LAYERS`] layers of equal height of a compact `height_m` high
/// (the lower punch at z = 0), by the height of their centres of mass (a
/// centre at or above the top counts in the top layer, one below 0 in the
/// bottom one). In single-ended pressing the die wall's friction holds
/// back the load on its way down, and the granules at the bottom of the
/// compact usually end less dense than those at its top.
pub fn density_by_height(granules: &[GranuleAtEnd], height_m: Real) -> Vec<DensityLayer> {
    let n = DENSITY_LAYERS;
    let mut sums = vec![(0_usize, 0.0); n];
    for g in granules {
        let at = (g.centre_m[2] / height_m * n as Real).floor();
        if at.is_nan() {
            continue;
        }
        let layer = (at.max(0.0) as usize).min(n - 1);
        sums[layer].0 += 1;
        sums[layer].1 += g.relative_density;
    }
    sums.iter()
        .enumerate()
        .map(|(k, &(count, sum))| DensityLayer {
            from_height: k as Real / n as Real,
            to_height: (k + 1) as Real / n as Real,
            granules: count,
            mean_relative_density: (count > 0).then(|| sum / count as Real),
        })
        .collect()
}

/// `summary.json`'s record of [`super::run::HiddenOverlap`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct HiddenOverlapSummary {
    /// Depth of the deepest surface node inside another granule, m (0: no
    /// node inside another granule; NaN: a surface node is not finite).
    pub depth_m: Real,
    /// That depth / the shortest surface edge of the reference mesh.
    pub rel_element: Option<Real>,
    /// The granule whose surface node it is (when the depth is not 0).
    pub granule: usize,
    /// The node, an index into the granule's nodes.
    pub node: usize,
    /// The granule it lies inside.
    pub inside_granule: usize,
    /// Wall time of the measurement, s (not in `wall_time_s`).
    pub wall_time_s: f64,
}

impl HiddenOverlapSummary {
    /// The record of `h` in a run whose element size is `element_m`.
    fn of(h: &super::run::HiddenOverlap, element_m: Real) -> Self {
        Self {
            depth_m: h.deepest.depth_m,
            rel_element: finite_ratio(h.deepest.depth_m, element_m),
            granule: h.deepest.granule,
            node: h.deepest.node,
            inside_granule: h.deepest.inside,
            wall_time_s: h.wall_time_s,
        }
    }
}

/// The summary of `run`.
pub fn summary<'a>(scene: &'a Scene, run: &BedRun) -> Summary<'a> {
    let last = run.samples.last().copied().unwrap_or_default();
    let k = kawakita(&run.samples, scene.kawakita_min_strain);
    let heckel_mean_pressure = heckel(run, scene.heckel_min_strain, mean_punch_pressure);
    let heckel_windows = FIT_WINDOWS.map(|c| heckel(run, c, upper_pressure)).to_vec();
    let heckel = heckel(run, scene.heckel_min_strain, upper_pressure);
    let kawakita_windows = FIT_WINDOWS.map(|c| kawakita(&run.samples, c)).to_vec();
    let min_jacobian = run
        .samples
        .iter()
        .map(|s| s.min_jacobian)
        .fold(Real::INFINITY, Real::min);
    let e = last.energies;
    let material = scene.material_params().ok();
    // NaN (a failed detection) propagates: `max` would drop it.
    let max_penetration_m = run
        .samples
        .iter()
        .map(|s| s.penetration_m)
        .fold(0.0, |m: Real, p| {
            if p.is_nan() || m.is_nan() {
                Real::NAN
            } else {
                m.max(p)
            }
        });
    let max_penetration_rel_element = finite_ratio(max_penetration_m, run.element_size_m);
    let certificate = quasi_static(&run.samples, run.rate_change_rel);
    let mut warnings = warnings(
        scene,
        run,
        (&k, &heckel),
        max_penetration_m,
        max_penetration_rel_element,
    );
    if let Some(w) = not_quasi_static(scene, run, &certificate) {
        warnings.push(w);
    }
    warnings.extend(run.unloading.as_ref().and_then(super::unloading::warning));
    let unloading = run.unloading.as_ref().map(|u| UnloadingSummary::of(run, u));
    warnings.extend(unloading.as_ref().and_then(super::unloading::rate_warning));
    Summary {
        format: FORMAT,
        format_version: FORMAT_VERSION,
        version: env!("CARGO_PKG_VERSION"),
        scene,
        scene_toml: scene.to_toml(),
        kawakita_a: k.a,
        kawakita_inv_b_pa: k.inv_b_pa,
        kawakita: k,
        heckel_yield_pressure_pa: heckel.yield_pressure_pa,
        heckel,
        kawakita_windows,
        heckel_windows,
        heckel_mean_pressure,
        initial_solid_fraction: bed_solid_fraction(run, 0.0),
        final_solid_fraction: bed_solid_fraction(run, last.strain),
        initial_packing_fraction: run
            .samples
            .first()
            .map_or(Real::NAN, |s| packing_fraction(run, s, s.strain)),
        final_packing_fraction: packing_fraction(run, &last, last.strain),
        quasi_static_strains: {
            let judged = granbed_kernel::analysis::quasi_static::judged(&run.samples);
            judged
                .first()
                .zip(judged.last())
                .map(|(a, b)| [a.strain, b.strain])
        },
        final_density_by_height: if run.final_granules.is_empty() {
            Vec::new()
        } else {
            density_by_height(&run.final_granules, final_height_m(run))
        },
        final_die_wall: die_wall_summary(run, &last),
        contact_network: Vec::new(),
        stress_by_height: Vec::new(),
        final_density_map: None,
        unloading,
        material: material.map(MaterialSummary::from),
        yield_stress_pa: material.map_or(Real::NAN, |m| m.yield_stress_pa),
        eta0: material.map_or(Real::NAN, |m| m.eta0),
        final_strain: last.strain,
        final_pressure_pa: last.upper_pressure_pa,
        final_relative_density: last.relative_density_mean,
        final_coordination: last.coordination,
        max_pressure_pa: run
            .samples
            .iter()
            .map(|s| s.upper_pressure_pa)
            .fold(0.0, Real::max),
        initial_bed_height_m: run.bed_height_m,
        granules: run.granules,
        elements: run.granules * run.hexes_per_granule,
        steps: run.steps,
        element_steps: run.element_steps,
        wall_time_s: run.wall_time_s,
        pour_wall_time_s: run.pour_wall_time_s,
        ns_per_element_step: finite_ratio(1e9 * run.wall_time_s, run.element_steps as f64),
        contact_share: Some(run.phase_times.contact_share()).filter(|x| x.is_finite()),
        contact_sweeps_per_step: run.phase_times.sweeps_per_step().filter(|x| x.is_finite()),
        face_list_builds_per_step: run.phase_times.per_step(run.phase_times.list_builds),
        anchor_renewals_per_step: run.phase_times.per_step(run.phase_times.anchor_renewals),
        pair_searches_per_step: run.phase_times.per_step(run.phase_times.pair_searches),
        rigid_granule_step_share: run.phase_times.rigid_share(run.granules),
        cost_figures_from_step: run.counters_from_step,
        threads: run.threads,
        min_jacobian,
        min_gauss_jacobian: run.samples.iter().map(|s| s.min_gauss_jacobian).fold(
            Real::INFINITY,
            |m: Real, j| {
                if j.is_nan() || m.is_nan() {
                    Real::NAN
                } else {
                    m.min(j)
                }
            },
        ),
        max_node_speed_ratio: finite_ratio(
            run.samples
                .iter()
                .map(|s| s.max_node_speed_m_s)
                .fold(0.0, Real::max),
            scene.punch_speed_m_s,
        ),
        max_penetration_m,
        max_penetration_rel_element,
        final_hidden_overlap: run
            .hidden_overlap
            .map(|h| HiddenOverlapSummary::of(&h, run.element_size_m)),
        hourglass_to_internal: finite_ratio(e.hourglass, e.internal_work),
        energy_residual_rel: finite_ratio(e.residual().abs(), e.punch_work),
        contact_loss_rel: finite_ratio(e.contact_loss(), e.punch_work),
        peak_memory_bytes: peak_memory_bytes(),
        quasi_static: certificate,
        added_mass: run.added_mass,
        interrupted: run.interrupted,
        warnings,
        error: run.error.as_ref().map(|e| e.to_string()),
    }
}

/// The warning of a run whose quasi-static certificate `q` fails (none
/// for a run stopped by an error, whose error says more): which figures
/// failed over which strains, and what slows the bed down. With its
/// figures, so that `--quiet` (which prints warnings) keeps them too.
fn not_quasi_static(scene: &Scene, run: &BedRun, q: &QuasiStatic) -> Option<String> {
    if q.passed || run.error.is_some() {
        return None;
    }
    let judged = granbed_kernel::analysis::quasi_static::judged(&run.samples);
    let from = judged.first().map_or(Real::NAN, |s| s.strain);
    let to = judged.last().map_or(Real::NAN, |s| s.strain);
    // Lighter masses are advice only where they are scaled up: 1 is the
    // physical mass and the smallest allowed.
    let lighter = if scene.mass_scaling > 1.0 {
        format!(
            " or lighter masses (--mass-scaling, now {})",
            scene.mass_scaling
        )
    } else {
        String::new()
    };
    // A coarse mesh's granules jump more: in a 100-granule bed measured
    // once (session 56), halving the speed on 4x1 took the ratio from 1.5
    // to 1.2 %, the standard mesh at full speed gave 0.5 %.
    let standard = crate::model::MeshLevel::STANDARD;
    let coarse = match scene.mesh_level() {
        Ok(level) if level.n <= standard.n && level.m <= standard.m && level != standard => {
            format!(
                "; a coarse mesh (now {}) rearranges by larger jumps than the standard {} mesh, \
             which a slower punch cures less",
                scene.mesh, standard
            )
        }
        _ => String::new(),
    };
    Some(format!(
        "NOT quasi-static over C = {from:.3} to {to:.3} (the second half of the output rows, \
         which the certificate judges): {}. Inertia is in these figures: a slower punch \
         (--punch-speed-m-s, now {} m/s){lighter} reduces it; a bed of few granules \
         rearranges by jumps whatever the speed{coarse}",
        q.figures(),
        scene.punch_speed_m_s,
    ))
}

/// The overlap above which a run is warned about: 1 % of the element size,
/// the criterion of `granbed-cli study stability` (issue #9's).
pub const OVERLAP_WARNING_REL: Real = crate::study::stability::MAX_PENETRATION_REL;

/// File name of the compression profile.
pub const COMPRESSION_CSV: &str = "compression.csv";
/// File name of the summary.
pub const SUMMARY_JSON: &str = "summary.json";

/// Why the Kawakita fit `k` does not describe a bed, if it does not: a
/// outside (0, 1] (a limiting strain; NaN included), 1/b ≤ 0, R² below
/// [`FIT_MIN_R_SQUARED`]. Empty for a fit inside the law's regime.
pub fn kawakita_doubts(k: &KawakitaSummary) -> Vec<String> {
    let mut why = Vec::new();
    if let Some(a) = k.a.filter(|&a| !(a > 0.0 && a <= 1.0)) {
        why.push(format!(
            "a = {a:.3} outside (0, 1] (a is the limiting strain)"
        ));
    }
    if let Some(inv_b) = k.inv_b_pa.filter(|&x| x <= 0.0) {
        why.push(format!("1/b = {inv_b:.3e} Pa <= 0"));
    }
    if let Some(r2) = k.r_squared.filter(|&r| !fit_linear(r)) {
        why.push(format!("R^2 = {r2:.3} < {FIT_MIN_R_SQUARED}"));
    }
    why
}

/// A note on a Kawakita fit `k` (inside the law's regime by
/// [`kawakita_doubts`]) whose a exceeds 1 − D0, `initial_solid_fraction`
/// D0 the poured bed's: extrapolated to infinite pressure it would press
/// the bed past its solid volume (D∞ = D0/(1 − a) > 1), so a is a figure of
/// the fitted window rather than the bed's limiting strain. A note, not a
/// rejection: fits over the reference study's C ≥ 0.25 give such an a for
/// the loosest types (A1 on the published scene fitted a = 0.719,
/// BENCHMARKS.md; its D0, estimated from B2's 0.425 × 0.6/0.8, leaves
/// 1 − D0 ≈ 0.68), and the published B2 scene lies just below (a = 0.556
/// against 0.575). `None` otherwise, or for a NaN D0.
pub fn kawakita_beyond_solid(k: &KawakitaSummary, initial_solid_fraction: Real) -> Option<String> {
    let a =
        k.a.filter(|&a| a > 0.0 && a <= 1.0 && a > 1.0 - initial_solid_fraction)?;
    Some(format!(
        "the Kawakita a = {a:.3} exceeds 1 - D0 = {:.3}: extrapolated to infinite pressure the \
         fit would press the bed past its solid volume (D0/(1 - a) = {:.2}), so a describes the \
         fitted window (C >= {}) rather than a limiting strain of the bed",
        1.0 - initial_solid_fraction,
        initial_solid_fraction / (1.0 - a),
        k.min_strain
    ))
}

/// Whether a fit (Kawakita's or Heckel's) with this R² is linear enough
/// for its figures to be material figures: R² at least
/// [`FIT_MIN_R_SQUARED`] (NaN is not). The one R² rule of the summary's
/// warnings, [`kawakita_doubts`] and the comparison tables' flags.
pub fn fit_linear(r_squared: Real) -> bool {
    r_squared >= FIT_MIN_R_SQUARED
}

/// A poured bed shallower than this many granule diameters is warned
/// about as a layer (the published scene's is about 9.6 diameters deep;
/// 100 granules in its 11.3 mm die pour to about 1.26, the CI-sized bed of
/// 30 in a 5 mm die to about 1.9).
pub const SHALLOW_BED_DIAMETERS: Real = 1.5;

/// The summary's warnings: `run.warnings`, then those its figures call
/// for.
fn warnings(
    scene: &Scene,
    run: &BedRun,
    (kawakita, heckel): (&KawakitaSummary, &HeckelSummary),
    max_penetration_m: Real,
    max_penetration_rel: Option<Real>,
) -> Vec<String> {
    let mut w = run.warnings.clone();
    if run.interrupted {
        w.push(format!(
            "interrupted (SIGINT/SIGTERM) at {}: the figures cover the run so far; \
             `granbed-cli bed --resume DIR` continues it from its checkpoint",
            run.stopped_at()
        ));
    }
    let diameter_m = scene.diameter_mm * 1e-3;
    if run.bed_height_m < SHALLOW_BED_DIAMETERS * diameter_m {
        w.push(format!(
            "the poured bed is {:.3} mm deep, less than {SHALLOW_BED_DIAMETERS} granule \
             diameters ({} mm): its granules touch mostly the punches, a layer rather than a \
             bed, and its figures are not a bed's; a narrower die (--die-diameter-mm, now {}) \
             or more granules (--granules, now {}) make it deeper",
            run.bed_height_m * 1e3,
            scene.diameter_mm,
            scene.die_diameter_mm,
            scene.granules
        ));
    }
    if let [.., before, last] = run.samples.as_slice() {
        let target = scene.final_strain;
        if last.strain > target + scene.output_strain_interval {
            let cause = if run.resumed_past_end {
                "the checkpoint resumed was already past it (a --strain below the strain the \
                 run had reached)"
                    .to_owned()
            } else {
                let per_step =
                    (last.strain - before.strain) / last.steps.saturating_sub(before.steps) as Real;
                format!(
                    "a step moves the punch by about C = {per_step:.3e}; a lower punch_speed_m_s \
                     (now {} m/s) or mass_scaling (now {}) takes smaller steps",
                    scene.punch_speed_m_s, scene.mass_scaling
                )
            };
            w.push(format!(
                "the run ended at C = {:.4}, past the final strain {target} by more than one \
                 output interval ({}): {cause}",
                last.strain, scene.output_strain_interval
            ));
        }
        if last.strain >= 1.0 {
            w.push(format!(
                "C = {:.4} >= 1: the upper punch has passed the lower punch's position; the \
                 figures of this run mean nothing",
                last.strain
            ));
        }
    }
    match max_penetration_rel {
        Some(r) if r > OVERLAP_WARNING_REL => w.push(format!(
            "granules overlap by up to {:.1} % of the element size ({max_penetration_m:.3e} m), \
             more than the {} % that `study stability` accepts: {OVERLAP_REMEDY}",
            100.0 * r,
            100.0 * OVERLAP_WARNING_REL
        )),
        None if max_penetration_m.is_nan() => {
            w.push("the granule overlap could not be measured (NaN)".to_owned());
        }
        _ => {}
    }
    if let Some(h) = &run.hidden_overlap {
        let d = h.deepest;
        match finite_ratio(d.depth_m, run.element_size_m) {
            Some(r) if r > OVERLAP_WARNING_REL => w.push(format!(
                "measured by geometry at the end of the run, node {} of granule {} lies {:.1} % \
                 of the element size ({:.3e} m) inside granule {}, more than the {} % that \
                 `study stability` accepts (the contact detection read at most {:.2} % at the \
                 output rows): {OVERLAP_REMEDY}",
                d.node,
                d.granule,
                100.0 * r,
                d.depth_m,
                d.inside,
                100.0 * OVERLAP_WARNING_REL,
                100.0 * max_penetration_rel.unwrap_or(Real::NAN)
            )),
            None if d.depth_m.is_nan() => w.push(format!(
                "the overlap by geometry could not be measured at the end of the run: node {} of \
                 granule {} is not finite",
                d.node, d.granule
            )),
            _ => {}
        }
    }
    if let Some(first) = run
        .samples
        .iter()
        .find(|s| bed_solid_fraction(run, s.strain) >= 1.0)
    {
        let last = run.samples.last().map_or(first.strain, |s| s.strain);
        w.push(format!(
            "the bed's solid fraction D (the granules' solid volume over the die cavity) reaches \
             1 at C = {:.3} ({:.3} at the end): the cavity is then smaller than the granules' \
             solid at rest, which the model's elastic solid (E = {} MPa) allows by compressing \
             it. ln(1/(1 - D)) (Heckel) is undefined from there, and the rows past it describe a \
             compressed solid, not a porous compact",
            first.strain,
            bed_solid_fraction(run, last),
            scene
                .material_params()
                .map_or(Real::NAN, |m| m.youngs_modulus_pa * 1e-6)
        ));
    }
    if let Some((from, min)) =
        first_fold(run.samples.iter().map(|s| (s.strain, s.min_gauss_jacobian)))
    {
        w.push(format!(
            "an element folded at a Gauss point from C = {from:.3} on (smallest Gauss-point \
             Jacobian ratio {min:.3} at the output rows; `study stability` accepts only > 0): \
             the one-point element's hourglass control (hourglass_kappa = {}) let a granule's \
             mesh fold, and the figures past that strain are doubtful. {FOLD_REMEDIES}",
            scene.hourglass_kappa
        ));
    }
    let why = kawakita_doubts(kawakita);
    if !why.is_empty() {
        w.push(format!(
            "the Kawakita fit over C >= {} ({} points) does not describe this bed: {}; its a \
             and 1/b are not material figures (a bed too small or a strain too short for the \
             law's regime; `--kawakita-min-strain` sets the window)",
            kawakita.min_strain,
            kawakita.points,
            why.join(", ")
        ));
    } else if let Some(note) = kawakita_beyond_solid(kawakita, bed_solid_fraction(run, 0.0)) {
        w.push(note);
    }
    for (law, min_strain, flag) in [
        ("Kawakita", kawakita.min_strain, "--kawakita-min-strain"),
        ("Heckel", heckel.min_strain, "--heckel-min-strain"),
    ] {
        // A run stopped or interrupted on purpose goes on later: no warning.
        let reached = run.samples.last().map_or(0.0, |s| s.strain);
        if min_strain > reached && !run.stopped && !run.interrupted {
            w.push(format!(
                "the {law} fit's window starts at C = {min_strain}, past the strain the run \
                 reached ({reached:.4}): no fit (`{flag}` sets the window)"
            ));
        }
    }
    if kawakita.a.is_none() && kawakita.points >= 2 {
        w.push(format!(
            "no Kawakita fit over C >= {} ({} points): the line P/C against P has no finite, \
             non-zero slope there (the pressures all equal, or P/C constant), so there is no a \
             or 1/b (`--kawakita-min-strain` sets the window)",
            kawakita.min_strain, kawakita.points
        ));
    }
    if heckel.yield_pressure_pa.is_none() && heckel.points >= 2 {
        w.push(format!(
            "no Heckel fit over C >= {} ({} points): ln(1/(1 - D)) does not rise with the \
             pressure there (K <= 0: the pressure fell while the bed densified, as in a bed \
             that still rearranges; or the pressures are all equal), so there is no yield \
             pressure (`--heckel-min-strain` sets the window)",
            heckel.min_strain, heckel.points
        ));
    }
    if let Some(r2) = heckel.r_squared.filter(|&r| !fit_linear(r)) {
        w.push(format!(
            "the Heckel fit over C >= {} ({} points) has R^2 = {r2:.3} < {FIT_MIN_R_SQUARED}: \
             ln(1/(1 - D)) is not linear in P there, and its yield pressure is not a material \
             figure (`--heckel-min-strain` sets the window)",
            heckel.min_strain, heckel.points
        ));
    }
    if run.counters_from_step > 0 {
        w.push(format!(
            "the cost figures (contact_share, contact_sweeps_per_step, \
             face_list_builds_per_step, anchor_renewals_per_step, pair_searches_per_step, \
             rigid_granule_step_share) cover steps {} to {} only: the run was resumed from a \
             checkpoint older than format 7, which did not carry them",
            run.counters_from_step, run.steps
        ));
    }
    w
}

/// What resolves overlaps above [`OVERLAP_WARNING_REL`], as measured
/// (BENCHMARKS.md, "Searching in every contact sweep from 30 %").
const OVERLAP_REMEDY: &str = "searching in every contact sweep \
     (`--exact-contact-from-strain C` from an earlier strain C, or `--hold-constraints false \
     --contact-search-interval 1` throughout) resolves it at a higher cost (on 30-granule 4x1 \
     beds to 60 %, held throughout: 26-44 % of the element; searching from 30 %: 0.7-0.8 %, at \
     2.7-3.9 times the wall time)";

/// What avoids a folded element, as measured (BENCHMARKS.md, "A folded
/// element warned about").
const FOLD_REMEDIES: &str = "On a 30-granule C3 bed of 4x1 granules whose element folded \
     at C = 0.595, each of these reached C = 0.6 without a fold: the 8x2 mesh (the published \
     one), hourglass_kappa = 0.1 (the pressure 5.6 % higher at C = 0.3) and element = \"fbar\" \
     (no hourglass modes); physical masses past C = 0.3 did not.";

/// The strain of the first output row whose smallest Gauss-point Jacobian
/// ratio is ≤ 0 (an element folded), and the smallest ratio of all rows;
/// `None` if no row folded. `rows`: (C, min Gauss-point J) per output row;
/// a NaN ratio (no deformable granule yet) is no fold.
fn first_fold(rows: impl Iterator<Item = (Real, Real)>) -> Option<(Real, Real)> {
    let mut fold: Option<(Real, Real)> = None;
    for (strain, j) in rows {
        if j <= 0.0 {
            fold = Some(match fold {
                Some((from, min)) => (from, min.min(j)),
                None => (strain, j),
            });
        } else if let Some((_, min)) = &mut fold {
            *min = min.min(j);
        }
    }
    fold
}

/// The R² below which the Kawakita and Heckel fits are warned about.
pub const FIT_MIN_R_SQUARED: Real = 0.9;

/// Writes `compression.csv`, `summary.json`, the plots and `report.html`
/// into `dir` (created).
pub fn write_all(dir: &Path, scene: &Scene, run: &BedRun) -> anyhow::Result<()> {
    crate::output::create_out_dir(dir)?;
    write_table(
        &dir.join(COMPRESSION_CSV),
        &COMPRESSION_COLUMNS,
        run.samples.iter().map(|s| row(s, run)),
    )?;
    let unloading_csv = dir.join(UNLOADING_CSV);
    match &run.unloading {
        Some(u) => write_table(
            &unloading_csv,
            &COMPRESSION_COLUMNS,
            u.samples.iter().map(|s| row(s, run)),
        )?,
        // A run without one leaves none from an earlier run in `dir`.
        None if unloading_csv.is_file() => std::fs::remove_file(&unloading_csv)
            .map_err(|e| anyhow::anyhow!("cannot remove `{}`: {e}", unloading_csv.display()))?,
        None => {}
    }
    let mut summary = summary(scene, run);
    let (network, left_out) = super::network::read_all(&dir.join(super::snapshots::VTK_DIR));
    summary.contact_network = network;
    summary.warnings.extend(left_out);
    let (profiles, left_out) =
        super::stress_profile::read_all(&dir.join(super::snapshots::VTK_DIR));
    let mu = summary.material.as_ref().map(|m| m.friction);
    summary.stress_by_height = profiles
        .iter()
        .map(|p| StressSummary::of(p, 0.5e-3 * scene.die_diameter_mm, mu))
        .collect();
    summary.warnings.extend(left_out);
    match super::density_map::read_last(&dir.join(super::snapshots::VTK_DIR)) {
        Ok(map) => summary.final_density_map = map,
        Err(e) => summary
            .warnings
            .push(format!("{e:#}; no final_density_map")),
    }
    write_json(&dir.join(SUMMARY_JSON), &summary)?;
    let svgs = super::plots::write_plots(dir, run, &summary)?;
    super::report::write_report(dir, scene, &summary, &svgs)
}

/// One line for stderr at the end.
pub fn summary_line(scene: &Scene, run: &BedRun) -> String {
    let s = summary(scene, run);
    let fmt =
        |x: Option<Real>, scale: Real| x.map_or("n/a".to_string(), |v| format!("{:.4}", v * scale));
    let q = s.quasi_static;
    let certificate = if q.passed {
        ""
    } else {
        "; NOT quasi-static (see the warning)"
    };
    format!(
        "bed {} x {}: C = {:.3} after {} steps in {:.1} s ({} thread{}, {:.0} ns/element-step); \
         max pressure {:.1} kPa; Kawakita a = {}, 1/b = {} kPa, R^2 = {} ({} points){}",
        scene.granules,
        scene.granule_type,
        s.final_strain,
        s.steps,
        s.wall_time_s,
        s.threads,
        if s.threads == 1 { "" } else { "s" },
        s.ns_per_element_step.unwrap_or(f64::NAN),
        s.max_pressure_pa * 1e-3,
        fmt(s.kawakita_a, 1.0),
        fmt(s.kawakita_inv_b_pa, 1e-3),
        fmt(s.kawakita.r_squared, 1.0),
        s.kawakita.points,
        certificate,
    )
}

/// The progress bar of a bed run on stderr (hidden with `--quiet` or when
/// stderr is not a terminal): strain as the position, with pressure,
/// coordination number, steps per second and the ETA. Drawn from the
/// run's first row on, so that a fresh run's pour shows its own line
/// alone (`bed`'s pour spinner).
pub struct Progress {
    quiet: bool,
    final_strain: Real,
    label: String,
    bar: Option<StrainBar>,
}

impl Progress {
    /// A bar up to `final_strain`, its line starting with `label`; not
    /// drawn before its first [`Progress::update`].
    pub fn new(quiet: bool, final_strain: Real, label: &str) -> Self {
        Self {
            quiet,
            final_strain,
            label: label.to_owned(),
            bar: None,
        }
    }

    /// The bar, drawn with the indicatif `template` if not drawn yet.
    fn bar(&mut self, template: &str) -> &StrainBar {
        let (quiet, label, final_strain) = (self.quiet, &self.label, self.final_strain);
        self.bar.get_or_insert_with(|| {
            let bar = ProgressBar::with_draw_target(None, draw_target(quiet));
            StrainBar::new(bar, template, label, final_strain)
        })
    }

    /// Shows sample `s`, taken `elapsed_s` into the compression.
    pub fn update(&mut self, s: &BedSample, elapsed_s: f64) {
        let bar = self.bar("{prefix} [{elapsed_precise}] {bar:30} C {msg} (ETA {eta})");
        bar.show(
            s.strain,
            format!(
                "{:.3}, P {:.1} kPa, Z {:.2}, {:.0} steps/s",
                s.strain,
                s.upper_pressure_pa * 1e-3,
                s.coordination,
                steps_per_second(s.steps, elapsed_s)
            ),
        );
    }

    /// Shows row `s` of the upper punch's withdrawal, `elapsed_s` into it:
    /// the bar full, the message the withdrawal's.
    pub fn withdrawing(&mut self, s: &BedSample, elapsed_s: f64) {
        let end = self.final_strain;
        let bar = self.bar("{prefix} [{elapsed_precise}] {bar:30} {msg}");
        bar.show(
            end,
            format!(
                "withdrawing the upper punch: C {:.4}, P {:.2} kPa, {:.0} s",
                s.strain,
                s.upper_pressure_pa * 1e-3,
                elapsed_s
            ),
        );
    }

    /// Removes the bar, if drawn.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// a must be a limiting strain in (0, 1]: 1 and 0.4 pass, 0, a
    /// negative a, a > 1 and NaN are doubted, each by name; 1/b ≤ 0 and a
    /// low R² too.
    #[test]
    fn a_kawakita_fit_outside_the_laws_regime_is_doubted() {
        let fit = |a: Real, inv_b: Real, r2: Real| KawakitaSummary {
            a: Some(a),
            inv_b_pa: Some(inv_b),
            r_squared: Some(r2),
            points: 11,
            min_strain: 0.25,
        };
        for a in [1.0, 0.4] {
            assert!(kawakita_doubts(&fit(a, 2e5, 0.99)).is_empty(), "a = {a}");
        }
        for a in [0.0, -6.8, 3.48, Real::NAN] {
            let why = kawakita_doubts(&fit(a, 2e5, 0.99));
            assert_eq!(why.len(), 1, "a = {a}: {why:?}");
            assert!(why[0].contains("outside (0, 1]"), "{why:?}");
        }
        // A bed poured to D0 = 0.39 ends at most solid: an a above 0.61 is
        // noted, not doubted (a session-56 review's 8x2 bed fitted 0.6456,
        // a D∞ of 1.10); an a outside (0, 1] is the doubt's alone.
        assert_eq!(kawakita_beyond_solid(&fit(0.6, 2e5, 0.99), 0.39), None);
        let note = kawakita_beyond_solid(&fit(0.6456, 2e5, 0.99), 0.39).unwrap();
        assert!(
            note.starts_with("the Kawakita a = 0.646 exceeds 1 - D0 = 0.610: ")
                && note.contains("(D0/(1 - a) = 1.10)"),
            "{note}"
        );
        assert!(kawakita_doubts(&fit(0.6456, 2e5, 0.99)).is_empty());
        assert_eq!(
            kawakita_beyond_solid(&fit(0.6456, 2e5, 0.99), Real::NAN),
            None
        );
        assert_eq!(kawakita_beyond_solid(&fit(3.48, 2e5, 0.99), 0.39), None);
        let why = kawakita_doubts(&fit(0.5, -1.0, 0.5));
        assert!(
            why[0].contains("1/b") && why[1].contains("R^2 = 0.500 < 0.9"),
            "{why:?}"
        );
        // No fit (too few points): nothing to doubt.
        let none = KawakitaSummary {
            a: None,
            inv_b_pa: None,
            r_squared: None,
            points: 2,
            min_strain: 0.25,
        };
        assert!(kawakita_doubts(&none).is_empty());
    }

    /// The warning of a failed certificate advises lighter masses only
    /// where the masses are scaled up; at the physical mass (1, the
    /// smallest allowed) only a slower punch.
    #[test]
    fn lighter_masses_are_advised_only_above_the_physical_mass() {
        use crate::bed::run::{BedRun, BedSample};
        let run = BedRun::of_samples(vec![BedSample::default(); 4]);
        let failed = QuasiStatic {
            max_kinetic_to_internal: Some(0.5),
            max_relative_kinetic_to_internal: None,
            force_imbalance_rel: Some(0.01),
            rate_change_rel: None,
            passed: false,
        };
        let mut scene = Scene::published();
        let scaled = not_quasi_static(&scene, &run, &failed).unwrap();
        assert!(
            scaled.contains("a slower punch (--punch-speed-m-s, now 0.05 m/s) or lighter masses (--mass-scaling, now 20) reduces it"),
            "{scaled}"
        );
        scene.mass_scaling = 1.0;
        let physical = not_quasi_static(&scene, &run, &failed).unwrap();
        assert!(
            physical.contains("a slower punch (--punch-speed-m-s, now 0.05 m/s) reduces it"),
            "{physical}"
        );
        assert!(!physical.contains("lighter"), "{physical}");
        // The mesh is named where it is coarser than the standard one.
        assert!(!physical.contains("coarse mesh"), "{physical}");
        scene.mesh = "4x1".into();
        let coarse = not_quasi_static(&scene, &run, &failed).unwrap();
        assert!(
            coarse.contains(
                "; a coarse mesh (now 4x1) rearranges by larger jumps than the standard 8x2 mesh"
            ),
            "{coarse}"
        );
        let passed = QuasiStatic {
            passed: true,
            ..failed
        };
        assert_eq!(not_quasi_static(&scene, &run, &passed), None);
    }

    /// A bed poured less than 1.5 granule diameters deep is warned about
    /// as a layer, naming its depth and what deepens it; a deeper one is
    /// not.
    #[test]
    fn a_bed_shallower_than_one_and_a_half_diameters_is_warned_about() {
        use crate::bed::run::{BedRun, BedSample};
        let scene = Scene::published();
        let mut run = BedRun::of_samples(vec![BedSample::default(); 4]);
        let kawakita = KawakitaSummary {
            a: None,
            inv_b_pa: None,
            r_squared: None,
            points: 0,
            min_strain: 0.25,
        };
        let heckel = HeckelSummary {
            yield_pressure_pa: None,
            k_per_pa: None,
            a: None,
            d_a: None,
            d_b: None,
            r_squared: None,
            points: 0,
            min_strain: 0.25,
        };
        let fits = (&kawakita, &heckel);
        let layer = |w: &[String]| w.iter().any(|w| w.contains("a layer rather than a bed"));
        run.bed_height_m = 1.26e-3;
        let w = warnings(&scene, &run, fits, 0.0, None);
        assert!(layer(&w), "{w:?}");
        assert!(
            w.iter().any(|w| w.starts_with(
                "the poured bed is 1.260 mm deep, less than 1.5 granule diameters (1 mm)"
            )),
            "{w:?}"
        );
        run.bed_height_m = 1.51e-3;
        assert!(!layer(&warnings(&scene, &run, fits, 0.0, None)));
    }

    /// The R² rule of both fits: 0.9 and above is linear, below it and NaN
    /// are not.
    #[test]
    fn a_fit_is_linear_from_r_squared_0_9() {
        assert!(fit_linear(0.9) && fit_linear(1.0));
        assert!(!fit_linear(0.899) && !fit_linear(Real::NAN));
    }

    /// A row with a Gauss-point Jacobian ratio ≤ 0 is a fold: the first
    /// such row's strain and the smallest ratio of all rows (a row that
    /// recovered included) are reported; NaN rows and positive ratios are
    /// not folds.
    #[test]
    fn the_first_folded_row_and_the_smallest_ratio_are_reported() {
        let rows = [(0.1, Real::NAN), (0.2, 0.4), (0.3, 0.01)];
        assert_eq!(first_fold(rows.into_iter()), None);
        let rows = [(0.1, 0.5), (0.55, -0.01), (0.575, 0.02), (0.6, -0.03)];
        assert_eq!(first_fold(rows.into_iter()), Some((0.55, -0.03)));
        assert_eq!(first_fold([(0.2, 0.0)].into_iter()), Some((0.2, 0.0)));
    }

    /// A run whose output rows saw a folded element says so in its
    /// summary's warnings, with the strain of the first folded row; a run
    /// without one does not.
    #[test]
    fn a_folded_element_is_warned_about_in_the_summary() {
        use crate::bed::run::{BedRun, BedSample};
        let run = |gauss: [Real; 4]| {
            BedRun::of_samples(
                gauss
                    .iter()
                    .enumerate()
                    .map(|(i, &min_gauss_jacobian)| BedSample {
                        strain: 0.1 * i as Real,
                        min_jacobian: 0.9,
                        min_gauss_jacobian,
                        ..BedSample::default()
                    })
                    .collect(),
            )
        };
        let scene = Scene::published();
        let folded = |w: &[String]| {
            w.iter()
                .find(|w| w.contains("folded at a Gauss point"))
                .cloned()
        };
        let w = summary(&scene, &run([1.0, 0.5, -0.02, 0.01])).warnings;
        let warning = folded(&w).unwrap_or_else(|| panic!("{w:?}"));
        assert!(
            warning.contains("from C = 0.200") && warning.contains("ratio -0.020"),
            "{warning}"
        );
        let w = summary(&scene, &run([1.0, 0.5, 0.2, 0.01])).warnings;
        assert_eq!(folded(&w), None, "{w:?}");
    }

    /// The overlap by geometry at the end of a run is recorded in the
    /// summary and warned about above 1 % of the element, naming the node,
    /// its granule and the granule it is inside; at 0.5 % it is recorded,
    /// not warned about; a non-finite node is named; a run that did not
    /// measure it records null.
    #[test]
    fn the_overlap_by_geometry_is_recorded_and_warned_about() {
        use crate::assembly::overlap::Overlap;
        use crate::bed::run::{BedRun, BedSample, HiddenOverlap};
        let run = |depth_m: Option<Real>| {
            let mut run = BedRun::of_samples(vec![BedSample::default()]);
            run.element_size_m = 1e-4;
            run.hidden_overlap = depth_m.map(|depth_m| HiddenOverlap {
                deepest: Overlap {
                    depth_m,
                    granule: 7,
                    node: 123,
                    inside: 9,
                },
                wall_time_s: 0.5,
            });
            run
        };
        let scene = Scene::published();
        let geometry = |w: &[String]| w.iter().find(|w| w.contains("by geometry")).cloned();
        let deep = summary(&scene, &run(Some(2e-6)));
        let record = deep.final_hidden_overlap.unwrap();
        assert!((record.rel_element.unwrap() - 0.02).abs() < 1e-15);
        assert_eq!(
            (record.granule, record.node, record.inside_granule),
            (7, 123, 9)
        );
        let warning = geometry(&deep.warnings).unwrap_or_else(|| panic!("{:?}", deep.warnings));
        assert!(
            warning.contains("node 123 of granule 7 lies 2.0 %")
                && warning.contains("inside granule 9"),
            "{warning}"
        );
        let shallow = summary(&scene, &run(Some(0.5e-6)));
        assert!((shallow.final_hidden_overlap.unwrap().rel_element.unwrap() - 0.005).abs() < 1e-15);
        assert_eq!(geometry(&shallow.warnings), None, "{:?}", shallow.warnings);
        let bad = summary(&scene, &run(Some(Real::NAN)));
        let warning = geometry(&bad.warnings).unwrap_or_else(|| panic!("{:?}", bad.warnings));
        assert!(
            warning.contains("node 123 of granule 7 is not finite"),
            "{warning}"
        );
        let none = summary(&scene, &run(None));
        assert!(none.final_hidden_overlap.is_none());
        assert_eq!(geometry(&none.warnings), None);
        let json = serde_json::to_value(&none).unwrap();
        assert!(json["final_hidden_overlap"].is_null());
    }

    /// A bed whose solid fraction D reaches 1 is warned about from the
    /// first row that reaches it (the unit die and bed of `of_samples`:
    /// D = 1/(π(1 − C)), 1 from C = 1 − 1/π ≈ 0.682); one that stays
    /// below is not.
    /// A run of healthy elements through the rows (strain, upper-punch
    /// pressure in Pa).
    fn run_of(rows: impl Iterator<Item = (Real, Real)>) -> crate::bed::run::BedRun {
        use crate::bed::run::{BedRun, BedSample};
        BedRun::of_samples(
            rows.map(|(strain, upper_pressure_pa)| BedSample {
                strain,
                upper_pressure_pa,
                min_jacobian: 0.9,
                min_gauss_jacobian: 0.9,
                ..BedSample::default()
            })
            .collect(),
        )
    }

    /// `kawakita_windows` refits the law over each window: rows of
    /// C = abP/(1 + bP) give a and 1/b back in every window the run
    /// reached, from that window's rows, and no figures past it; the window
    /// at the scene's start is the run's own fit.
    #[test]
    fn the_kawakita_fit_is_repeated_over_each_window() {
        let (a, inv_b) = (0.4, 50e3);
        let scene = Scene::published();
        for last in [22, 28] {
            let strains = || (1..=last).map(|i| 0.01 * Real::from(i));
            let run = run_of(strains().map(|c| (c, c * inv_b / (a - c))));
            let s = summary(&scene, &run);
            assert_eq!(s.kawakita_windows.len(), FIT_WINDOWS.len());
            for (k, &from) in s.kawakita_windows.iter().zip(&FIT_WINDOWS) {
                assert_eq!(k.min_strain, from);
                let rows = strains().filter(|&c| c >= from).count();
                assert_eq!(k.points, rows, "{k:?}");
                if rows >= 2 {
                    let rel = |x: Option<Real>, want: Real| (x.unwrap() - want).abs() / want;
                    assert!(rel(k.a, a) < 1e-9 && rel(k.inv_b_pa, inv_b) < 1e-9, "{k:?}");
                } else {
                    assert!(k.a.is_none() && k.inv_b_pa.is_none(), "{k:?}");
                }
            }
            let own = s
                .kawakita_windows
                .iter()
                .find(|k| k.min_strain == 0.25)
                .unwrap();
            assert_eq!(own.points, if last == 28 { 4 } else { 0 });
            assert_eq!(
                (own.points, own.a, own.inv_b_pa, own.r_squared),
                (
                    s.kawakita.points,
                    s.kawakita.a,
                    s.kawakita.inv_b_pa,
                    s.kawakita.r_squared
                )
            );
        }
    }

    /// The die wall's figures of a row: its pressure over the wall beside
    /// the compact at the mean strain, the two ratios; none where the force
    /// was not recorded or a divisor is not positive.
    #[test]
    fn the_die_wall_figures_of_a_row() {
        use crate::bed::run::{BedRun, BedSample};
        // of_samples' bed: R_d = 1 m, H0 = 1 m.
        let run = BedRun::of_samples(Vec::new());
        let row = BedSample {
            mean_strain: 0.2,
            die_normal_force_n: 2.0 * core::f64::consts::PI * 0.8 * 500.0,
            die_friction_z_n: -40.0,
            upper_pressure_pa: 1200.0,
            lower_pressure_pa: 800.0,
            ..BedSample::default()
        };
        let w = die_wall_summary(&run, &row);
        assert!((w.pressure_pa.unwrap() - 500.0).abs() < 1e-12);
        assert_eq!(w.mean_punch_pressure_pa, Some(1000.0));
        assert!((w.radial_to_axial.unwrap() - 0.5).abs() < 1e-15);
        assert!((w.radial_to_upper.unwrap() - 500.0 / 1200.0).abs() < 1e-15);
        assert!((w.friction_to_normal.unwrap() - 40.0 / row.die_normal_force_n).abs() < 1e-15);
        let unrecorded = die_wall_summary(
            &run,
            &BedSample {
                die_normal_force_n: Real::NAN,
                ..row
            },
        );
        assert_eq!(
            (
                unrecorded.pressure_pa,
                unrecorded.radial_to_axial,
                unrecorded.radial_to_upper,
                unrecorded.friction_to_normal
            ),
            (None, None, None, None)
        );
        // The upper punch unloaded, the lower one not: no ratio to it.
        let upper_free = die_wall_summary(
            &run,
            &BedSample {
                upper_pressure_pa: 0.0,
                ..row
            },
        );
        assert_eq!(upper_free.radial_to_upper, None);
        assert!((upper_free.radial_to_axial.unwrap() - 500.0 / 400.0).abs() < 1e-15);
        let unloaded = die_wall_summary(
            &run,
            &BedSample {
                die_normal_force_n: 0.0,
                upper_pressure_pa: 0.0,
                lower_pressure_pa: 0.0,
                ..row
            },
        );
        assert_eq!(unloaded.pressure_pa, Some(0.0));
        assert_eq!(
            (
                unloaded.radial_to_axial,
                unloaded.radial_to_upper,
                unloaded.friction_to_normal
            ),
            (None, None, None)
        );
    }

    /// The fits pair each row's pressure, an average over its output
    /// interval, with the interval's mean strain: a law that holds there
    /// is recovered exactly.
    #[test]
    fn the_fits_pair_the_averaged_pressure_with_the_mean_strain() {
        use crate::bed::run::{BedRun, BedSample};
        // Kawakita's law C = abP/(1 + bP), a = 0.4, 1/b = 20 kPa, holding
        // at each interval's mean strain: rows every 0.005, 129 equal steps
        // each, the pressure that of the mean of C over the steps' ends.
        let (a, inv_b, n) = (0.4, 20e3, 129_u64);
        let law = |c: Real| inv_b * c / (a - c);
        let samples: Vec<BedSample> = (0..=60_u32)
            .map(|i| {
                let c = 0.005 * Real::from(i);
                let before = c - 0.005;
                let mean = (1..=n)
                    .map(|k| before + 0.005 * k as Real / n as Real)
                    .sum::<Real>()
                    / n as Real;
                BedSample {
                    strain: c,
                    steps: n * u64::from(i),
                    upper_pressure_pa: if i == 0 { 0.0 } else { law(mean) },
                    min_jacobian: 0.9,
                    min_gauss_jacobian: 0.9,
                    ..BedSample::default()
                }
            })
            .collect();
        let run = BedRun::of_samples(samples);
        let scene = Scene::published();
        let s = summary(&scene, &run);
        let rel = |x: Option<Real>, want: Real| (x.unwrap() - want).abs() / want;
        assert!(rel(s.kawakita.a, a) < 1e-9, "{:?}", s.kawakita);
        assert!(rel(s.kawakita.inv_b_pa, inv_b) < 1e-9, "{:?}", s.kawakita);
        // The rows with a mean strain ≥ 0.25: from C = 0.255 on.
        assert_eq!(s.kawakita.points, 10);
        // Paired with the rows' end strains instead, the same data is off
        // by more than a per cent: the test tells the two apart.
        let at_end = granbed_kernel::analysis::bed::kawakita_fit(
            run.samples.iter().map(|s| (s.upper_pressure_pa, s.strain)),
            0.25,
        )
        .unwrap();
        assert!((at_end.inv_b_pa - inv_b).abs() / inv_b > 0.01, "{at_end:?}");
        // The Heckel rows take D at the mean strain too.
        for (s, (_, d, c)) in run.samples.iter().zip(heckel_rows(&run, upper_pressure)) {
            assert_eq!(c, s.mean_strain);
            assert_eq!(d, bed_solid_fraction(&run, s.mean_strain));
        }
    }

    /// The Heckel fit on the mean punch pressure: rows whose mean pressure
    /// follows ln(1/(1 − D)) = P/P_y + A exactly, with the upper punch
    /// carrying a quarter more (the wall's share), give P_y back on the
    /// mean pressure and 1.25 P_y on the upper one, in every window.
    #[test]
    fn the_heckel_fit_on_the_mean_punch_pressure() {
        use crate::bed::run::{BedRun, BedSample};
        let (p_y, a) = (80e3, 0.3);
        let samples = (0..=30)
            .map(|i| {
                let c = 0.01 * Real::from(i);
                // of_samples' bed: D = 1/(π (1 − C)).
                let d = 1.0 / (core::f64::consts::PI * (1.0 - c));
                let mean = (-(-d).ln_1p() - a) * p_y;
                BedSample {
                    strain: c,
                    upper_pressure_pa: 1.25 * mean,
                    lower_pressure_pa: 0.75 * mean,
                    min_jacobian: 0.9,
                    min_gauss_jacobian: 0.9,
                    ..BedSample::default()
                }
            })
            .collect();
        let scene = Scene::published();
        let s = summary(&scene, &BedRun::of_samples(samples));
        let rel = |x: Option<Real>, want: Real| (x.unwrap() - want).abs() / want;
        let mean = s.heckel_mean_pressure;
        assert!(rel(mean.yield_pressure_pa, p_y) < 1e-9, "{mean:?}");
        assert!(rel(mean.a, a) < 1e-9, "{mean:?}");
        assert!(
            rel(s.heckel.yield_pressure_pa, 1.25 * p_y) < 1e-9,
            "{:?}",
            s.heckel
        );
        assert_eq!((mean.points, mean.min_strain), (6, 0.25));
        // The upper punch's law again over each window, from its rows.
        for (w, &from) in s.heckel_windows.iter().zip(&FIT_WINDOWS) {
            assert_eq!(w.min_strain, from);
            assert_eq!(
                w.points,
                (0..=30).filter(|&i| 0.01 * Real::from(i) >= from).count()
            );
            assert!(rel(w.yield_pressure_pa, 1.25 * p_y) < 1e-9, "{w:?}");
        }
    }

    /// Granules go to the layer of their centre's height, a centre at or
    /// above the top to the top layer, one below the bottom to the bottom
    /// one, a NaN height to none; an empty layer has no mean.
    #[test]
    fn granule_densities_are_averaged_by_layer() {
        let at = |z: Real, relative_density: Real| GranuleAtEnd {
            centre_m: [0.0, 0.0, z],
            relative_density,
        };
        let height = 2.0;
        let granules = [
            at(0.1, 0.70),
            at(-0.01, 0.72),
            at(0.5, 0.80),
            at(1.9, 0.90),
            at(2.0, 0.94),
            at(2.3, 0.92),
            at(Real::NAN, 0.5),
        ];
        let layers = density_by_height(&granules, height);
        assert_eq!(layers.len(), DENSITY_LAYERS);
        let counts: Vec<usize> = layers.iter().map(|l| l.granules).collect();
        assert_eq!(counts, [2, 1, 0, 0, 3]);
        let close = |m: Option<Real>, want: Real| (m.unwrap() - want).abs() < 1e-15;
        assert!(close(layers[0].mean_relative_density, 0.71));
        assert!(close(layers[1].mean_relative_density, 0.80));
        assert!(layers[2].mean_relative_density.is_none());
        assert!(close(layers[4].mean_relative_density, 0.92));
        assert_eq!((layers[1].from_height, layers[1].to_height), (0.2, 0.4));
    }

    #[test]
    fn a_solid_fraction_of_one_is_warned_about() {
        let run = |strains: &[Real]| run_of(strains.iter().map(|&c| (c, 0.0)));
        let scene = Scene::published();
        let solid = |w: &[String]| w.iter().find(|w| w.contains("solid fraction D")).cloned();
        let w = summary(&scene, &run(&[0.0, 0.5, 0.7, 0.75])).warnings;
        let warning = solid(&w).unwrap_or_else(|| panic!("{w:?}"));
        assert!(
            warning.contains("reaches 1 at C = 0.700 (1.273 at the end)"),
            "{warning}"
        );
        let w = summary(&scene, &run(&[0.0, 0.5, 0.68])).warnings;
        assert_eq!(solid(&w), None, "{w:?}");
    }

    /// Rows in a fit's window from which no fit can be made are warned
    /// about, for either law, with the window and the points: equal
    /// pressures (no line); rows that make a fit are not.
    #[test]
    fn a_fit_that_cannot_be_made_is_warned_about() {
        let run = |pressures: &[Real]| {
            run_of(
                pressures
                    .iter()
                    .enumerate()
                    .map(|(i, &p)| (0.25 + 0.01 * i as Real, p)),
            )
        };
        let scene = Scene::published();
        let refused = |w: &[String], law: &str| {
            w.iter()
                .find(|w| w.starts_with(&format!("no {law} fit over C >= 0.25 (3 points)")))
                .cloned()
        };
        let flat = summary(&scene, &run(&[5e3, 5e3, 5e3]));
        assert!(flat.kawakita.a.is_none() && flat.heckel.yield_pressure_pa.is_none());
        for law in ["Kawakita", "Heckel"] {
            assert!(
                refused(&flat.warnings, law).is_some(),
                "{law}: {:?}",
                flat.warnings
            );
        }
        let rising = summary(&scene, &run(&[5e3, 6e3, 7e3]));
        assert!(rising.heckel.yield_pressure_pa.is_some());
        for law in ["Kawakita", "Heckel"] {
            assert_eq!(refused(&rising.warnings, law), None, "{law}");
        }
    }
}
