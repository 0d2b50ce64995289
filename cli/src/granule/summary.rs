//! The measures of one single-granule run (`summary.json`): σ_est from the
//! force–displacement slope, σ_y,eff0, the energy checks, the cost, and
//! every input parameter for provenance.

use crate::output::finite_ratio as ratio;
use granbed_kernel::Real;
use granbed_kernel::analysis::granule::initial_effective_yield_stress;
use granbed_kernel::granule::forces::ElementKind;
use granbed_kernel::granule::timestep::TimeStepMethod;
use granbed_kernel::scene::platens::{PlatenParams, PlatenSample, SceneError, Symmetry};
use serde::Serialize;

use super::run::RunResult;
use crate::material_args::MaterialSummary;
use crate::model::MeshLevel;
use crate::quasi_static::QuasiStatic;

/// Name of the `summary.json` format (its `format` field).
pub const FORMAT: &str = "granbed-granule-summary";
/// Version of the `summary.json` format; bumped when a field changes
/// meaning or disappears (adding a field does not bump it).
///
/// 2: `sigma_est_strain_range` is the strain range the fit covered (null
/// without a fit), no longer always the nominal [0.1, 0.4].
/// 3: `element` is spelt as the `--element` flag (`fbar`, was `f-bar`),
/// and `force_displacement.csv`'s `min_j` is `min_jacobian`, as in the
/// bed's tables (`_j` is the joule columns' suffix).
pub const FORMAT_VERSION: u32 = 3;

pub use granbed_kernel::analysis::granule::FIT_STRAIN_RANGE;

/// The command-line name of a symmetry mode (`octant` or `full`).
pub fn symmetry_name(s: Symmetry) -> &'static str {
    match s {
        Symmetry::Octant => "octant",
        Symmetry::Full => "full",
    }
}

/// What was run: the inputs of a summary that are not in [`PlatenParams`].
#[derive(Clone, Copy, Debug)]
pub struct RunSetup<'a> {
    /// Granule type name the material preset came from, e.g. `B2`.
    pub granule_type: &'a str,
    /// Mesh level of the full sphere.
    pub mesh: MeshLevel,
    /// Nodes of the simulated (octant or full) mesh.
    pub nodes: usize,
    /// Hexes of the simulated mesh.
    pub hexes: usize,
    /// The experiment's parameters.
    pub params: &'a PlatenParams,
}

/// `summary.json`: one run's inputs and measures. Units are in the field
/// names; a measure that cannot be computed (too few samples, zero
/// denominator) is `null`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Always [`FORMAT`].
    pub format: &'static str,
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Version of granbed that wrote the file.
    pub granbed_version: &'static str,
    /// Granule type of the material preset, e.g. `B2` (overrides below).
    pub granule_type: String,
    /// Mesh level `NxM` of the full sphere.
    pub mesh: String,
    /// `octant` or `full`.
    pub symmetry: &'static str,
    /// Nodes simulated.
    pub mesh_nodes: usize,
    /// Hexes simulated.
    pub mesh_hexes: usize,
    /// Granule diameter d, m.
    pub diameter_m: Real,

    /// The material, its fields at this level of the file (friction:
    /// the granule–platen contact's).
    #[serde(flatten)]
    pub material: MaterialSummary,

    /// Element formulation: `one-point` (production) or `fbar`.
    pub element: &'static str,
    /// Requested final strain (platen approach / d).
    pub target_strain: Real,
    /// Platen approach speed, m/s.
    pub approach_speed_m_s: Real,
    /// Damping ratio ξ.
    pub damping_ratio: Real,
    /// Hourglass coefficient κ.
    pub hourglass_kappa: Real,
    /// True if the return map ran without the volume-drift fix.
    pub literal_return: bool,
    /// Relative yield tolerance of the constitutive update.
    pub yield_tolerance: Real,
    /// Safety factor C of the time step.
    pub time_step_safety: Real,
    /// Steps between time-step re-estimates.
    pub time_step_interval: u32,
    /// Time-step estimate: "global" (power iteration) or "element".
    pub time_step_method: &'static str,
    /// Strain between samples.
    pub output_strain_interval: Real,
    /// Gravity, m/s² (in −z).
    pub gravity_m_s2: Real,
    /// Uniform mass scaling F (masses ×F, gravity ÷F).
    pub mass_scaling: Real,

    /// Granule yield stress estimate σ_est = 4/(πd)·dF/dx over
    /// [`Summary::sigma_est_strain_range`], Pa; `null` with fewer than two
    /// samples in range.
    pub sigma_est_pa: Option<Real>,
    /// Strain range the fit actually covered, x/d: the first and the last
    /// sample within [`FIT_STRAIN_RANGE`], each end widened by half an
    /// output interval, at most 0.05 ([`granbed_kernel::analysis::granule::fit_window`]: a sample lies up to a step past its
    /// nominal strain, so the 40 % sample is 0.4000019) (narrower when the run ends
    /// before 0.4, or when the output interval places no sample nominally
    /// near 0.1 (its multiples miss 0.1 by more than a quarter interval),
    /// which `notes` and stderr then say); `null` without a fit.
    pub sigma_est_strain_range: Option<[Real; 2]>,
    /// σ_y,eff0 = √a2(η0)·σ_y, Pa.
    pub sigma_eff0_pa: Real,
    /// Fitted slope dF/dx, N/m.
    pub slope_n_per_m: Option<Real>,
    /// Fitted intercept, N.
    pub intercept_n: Option<Real>,
    /// R² of the fit.
    pub fit_r_squared: Option<Real>,
    /// Samples in the fit.
    pub fit_points: usize,
    /// Samples written (rows of `force_displacement.csv`).
    pub samples: usize,
    /// Time steps taken.
    pub steps: u64,
    /// Initial time step, s.
    pub dt_s: Real,
    /// Time step at the last sample, s.
    pub final_dt_s: Real,
    /// Element evaluations (steps × hexes simulated).
    pub element_steps: u64,
    /// Wall time of the run (stepping and sampling), s.
    pub wall_time_s: f64,
    /// Wall time per element evaluation, ns.
    pub ns_per_element_step: Option<f64>,
    /// Energy-balance residual / contact work at the last sample (round-off
    /// by construction).
    pub energy_residual_rel: Option<Real>,
    /// Return-map energy gap / contact work at the last sample.
    pub return_map_gap_rel: Option<Real>,
    /// Hourglass energy / internal work at the last sample.
    pub hourglass_energy_rel: Option<Real>,
    /// Damping dissipation / contact work at the last sample.
    pub damping_rel: Option<Real>,
    /// Smallest element J over all samples.
    pub min_jacobian: Real,
    /// The quasi-static certificate over the second half of the samples
    /// (the platen force imbalance is measured with full symmetry only).
    pub quasi_static: QuasiStatic,
    /// Strain of the last sample.
    pub final_strain: Real,
    /// Largest mean platen force over the samples, N.
    pub max_force_n: Real,
    /// Remarks on the measures (e.g. why σ_est is null).
    pub notes: Vec<String>,
    /// The kernel error that stopped the run, or `null`.
    pub error: Option<String>,
}

impl Summary {
    /// The summary of `result`, a run of `setup`; `rate_change_rel` is the
    /// rate check's change of the force curve, if it ran.
    pub fn new(setup: &RunSetup<'_>, result: &RunResult, rate_change_rel: Option<Real>) -> Self {
        let p = setup.params;
        let m = &p.material.params;
        let samples = &result.samples;
        let last = samples.last();
        let [lo, hi] = FIT_STRAIN_RANGE;
        let sigma_est =
            PlatenSample::sigma_est(samples, result.diameter_m, p.output_strain_interval);
        let final_strain = last.map_or(0.0, |s| s.strain);
        let fitted_range = sigma_est.map(|s| s.strain_range);
        let fit = sigma_est.map(|s| (s.sigma_pa, s.fit));
        let mut notes = Vec::new();
        match fitted_range {
            None if final_strain < hi => notes.push(format!(
                "sigma_est needs at least two samples with {lo} <= strain <= {hi}; the run \
                 ended at strain {final_strain:.4}"
            )),
            None => notes.push(format!(
                "sigma_est needs at least two samples with {lo} <= strain <= {hi}; the output \
                 interval {} places fewer there",
                p.output_strain_interval
            )),
            Some([a, b]) if final_strain < hi => notes.push(format!(
                "sigma_est was fitted over strain {a:.4} to {b:.4} only, not {lo} to {hi}: the \
                 run ended at strain {final_strain:.4}"
            )),
            // The first fitted sample's nominal strain (the interval's
            // multiple below it: a sample lies up to a step past its nominal
            // strain, never before) more than a quarter interval above 10 %:
            // none was written nominally near 10 %.
            Some([a, b])
                if nominal_at_or_below(a, p.output_strain_interval)
                    > lo + 0.25 * p.output_strain_interval =>
            {
                notes.push(format!(
                    "sigma_est was fitted over strain {a:.4} to {b:.4} only, not {lo} to {hi}: \
                     the output interval {} places no sample near {lo}",
                    p.output_strain_interval
                ));
            }
            Some(_) => {}
        }
        let e = last.map(|s| s.energy).unwrap_or_default();
        Self {
            format: FORMAT,
            format_version: FORMAT_VERSION,
            granbed_version: env!("CARGO_PKG_VERSION"),
            granule_type: setup.granule_type.to_owned(),
            mesh: setup.mesh.to_string(),
            symmetry: symmetry_name(p.symmetry),
            mesh_nodes: setup.nodes,
            mesh_hexes: setup.hexes,
            diameter_m: result.diameter_m,
            material: MaterialSummary {
                friction: p.friction,
                ..MaterialSummary::from(*m)
            },
            element: match p.elements.kind {
                ElementKind::OnePoint => "one-point",
                ElementKind::FBar => "fbar",
            },
            target_strain: p.final_strain,
            approach_speed_m_s: p.approach_speed_m_s,
            damping_ratio: p.damping_ratio,
            hourglass_kappa: p.elements.hourglass_kappa,
            literal_return: !p.elements.update.volume_fix,
            yield_tolerance: p.elements.update.yield_tolerance,
            time_step_safety: p.time_step_safety,
            time_step_interval: p.time_step_interval,
            time_step_method: match p.time_step_method {
                TimeStepMethod::Element => "element",
                TimeStepMethod::Global { .. } => "global",
            },
            output_strain_interval: p.output_strain_interval,
            gravity_m_s2: p.gravity_m_s2,
            mass_scaling: p.mass_scaling,
            sigma_est_pa: fit.map(|(sigma, _)| sigma),
            sigma_est_strain_range: fitted_range,
            sigma_eff0_pa: initial_effective_yield_stress(m),
            slope_n_per_m: fit.map(|(_, f)| f.slope),
            intercept_n: fit.map(|(_, f)| f.intercept),
            fit_r_squared: fit.and_then(|(_, f)| f.r_squared.is_finite().then_some(f.r_squared)),
            fit_points: fit.map_or(0, |(_, f)| f.points),
            samples: samples.len(),
            steps: result.steps,
            dt_s: result.initial_dt_s,
            final_dt_s: last.map_or(result.initial_dt_s, |s| s.dt_s),
            element_steps: result.element_steps,
            wall_time_s: result.wall_time_s,
            ns_per_element_step: ratio(result.wall_time_s * 1.0e9, result.element_steps as f64),
            energy_residual_rel: ratio(e.residual(), e.contact_work),
            return_map_gap_rel: ratio(e.return_map_gap(), e.contact_work),
            hourglass_energy_rel: ratio(e.hourglass, e.internal_work),
            damping_rel: ratio(e.damping, e.contact_work),
            min_jacobian: samples.iter().fold(Real::INFINITY, |j, s| j.min(s.min_j)),
            quasi_static: PlatenSample::certificate(samples, p.symmetry, rate_change_rel).into(),
            final_strain,
            max_force_n: samples
                .iter()
                .fold(Real::NEG_INFINITY, |f, s| f.max(s.mean_force())),
            notes,
            error: result.error.as_ref().map(SceneError::to_string),
        }
    }

    /// The stderr warning of a run that failed the quasi-static
    /// certificate, with its figures.
    pub fn not_quasi_static(&self) -> String {
        format!(
            "granule {}: NOT quasi-static with mass scaling {} ({})",
            self.granule_type,
            self.mass_scaling,
            self.quasi_static.figures()
        )
    }

    /// The one-line stderr report of the run.
    pub fn line(&self) -> String {
        let sigma_est = self
            .sigma_est_pa
            .map_or_else(|| "n/a".to_owned(), |s| format!("{s:.4e} Pa"));
        let ns = self
            .ns_per_element_step
            .map_or_else(|| "n/a".to_owned(), |ns| format!("{ns:.1}"));
        format!(
            "granule {} ({} {}) to strain {:.4}: sigma_est {sigma_est}, sigma_eff0 {:.4e} Pa, \
             {} steps, {:.3} s, {ns} ns/element-step",
            self.granule_type,
            self.mesh,
            self.symmetry,
            self.final_strain,
            self.sigma_eff0_pa,
            self.steps,
            self.wall_time_s
        )
    }
}
/// The multiple of `interval` at or just below the strain `c` (a sample's
/// nominal strain: samples lie up to a step past it, never before; 10⁻⁹ of
/// an interval of round-off taken as on it).
fn nominal_at_or_below(c: Real, interval: Real) -> Real {
    (c / interval + 1e-9).floor() * interval
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample's nominal strain is the interval's multiple at or below it,
    /// however far a step carried it past (up to a whole interval): the
    /// default interval's 10 % sample stays at 10 % at a fast platen, and
    /// an interval of 0.06 puts the first sample past 10 % at 12 %.
    #[test]
    fn a_sample_past_its_nominal_strain_keeps_it() {
        let close = |a: Real, b: Real| (a - b).abs() < 1e-12;
        assert!(close(nominal_at_or_below(0.100_010_7, 0.005), 0.1));
        assert!(close(nominal_at_or_below(0.103_8, 0.005), 0.1));
        assert!(close(nominal_at_or_below(0.120_000_4, 0.06), 0.12));
        assert!(close(nominal_at_or_below(0.2, 0.2), 0.2));
    }
}
