//! The single-granule experiment: one granule compressed between two rigid
//! platens that approach each other at constant speed (physics.md §4.1, §5.5,
//! §7 item 7). It lives in the kernel over caller buffers so the CLI and the
//! browser run the same code and get the same bits.
//!
//! One step (central differences, Pronto-style predictor/corrector contact):
//! 1. element forces f_int(x_n);
//! 2. selective damping forces f_d from v_{n−½};
//! 3. v* = v_{n−½} + Δt_n M⁻¹(f_g − f_int + f_d);
//! 4. predictor x̃ = x_n + Δt v*, platens at t_{n+1};
//! 5. platen contact forces f_c on x̃;
//! 6. v_{n+½} = v* + Δt_n M⁻¹f_c, x_{n+1} = x_n + Δt v_{n+½};
//! 7. energies and platen forces.
//!
//! Both platens move toward the centre at half the approach speed. In
//! [`Symmetry::Octant`] mode only the positive octant of the mesh is
//! simulated: the planes x = 0, y = 0, z = 0 are symmetry planes, the lower
//! platen is the mirror image of the upper one, and forces (×4) and energies
//! (×8) are reported for the whole granule.

use core::fmt;

use crate::Real;
use crate::contact::pair::ContactError;
use crate::contact::rigid::RigidShift;
use crate::contact::wall::{Plane, PredictedNodes, plane_contact};
use crate::granule::damping::damping_coefficient;
use crate::granule::dynamics::{GranuleBuffers, Loads, StepSizes, correct, predict};
use crate::granule::forces::{
    ElementKind, ElementSettings, ForcesError, check_element_buffers, elastic_energy,
};
use crate::granule::quality::{WorstElement, worst_element};
use crate::granule::timestep::{
    Linearisation, PowerIterationBuffers, TimeStepControl, TimeStepMethod, power_start,
};
use crate::material::Material;
use crate::math;
use crate::mesh::reference::ReferenceMesh;
use crate::mesh::sphere::MeshError;

/// Which part of the granule is simulated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// The positive octant, with three symmetry planes (1/8 of the work).
    Octant,
    /// The whole granule.
    Full,
}

/// Parameters of the platen experiment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlatenParams {
    /// The granule's material.
    pub material: Material,
    /// Element settings (constitutive switches, hourglass κ).
    pub elements: ElementSettings,
    /// Fraction ξ of critical damping of the lowest deformational mode; 0 ≤ ξ ≤ 2.
    pub damping_ratio: Real,
    /// Speed at which the platens approach each other, m/s; 0 < v ≤ 10.
    pub approach_speed_m_s: Real,
    /// Coulomb friction between granule and platens; 0 ≤ μ ≤
    /// [`crate::material::MAX_FRICTION`] (10).
    pub friction: Real,
    /// Platen approach / diameter at which the run ends; 0 < strain ≤ 0.9.
    pub final_strain: Real,
    /// Safety factor C of the element time-step estimate; 0 < C ≤ 1.
    pub time_step_safety: Real,
    /// Steps between time-step re-estimates; ≥ 1.
    pub time_step_interval: u32,
    /// Element or global (power-iteration) estimate of the stable step.
    pub time_step_method: TimeStepMethod,
    /// Strain between output samples (forces are averaged over it); > 0.
    pub output_strain_interval: Real,
    /// Gravity (acting in −z), m/s²; ≥ 0, and 0 in octant mode.
    pub gravity_m_s2: Real,
    /// Octant or full granule.
    pub symmetry: Symmetry,
    /// Uniform mass scaling F (1 ≤ F ≤ 10⁶): every nodal mass ×F, gravity
    /// ÷F (the weight is kept), so the stable step grows by √F; the damping
    /// ratio applies to the scaled granule. Whether a run stayed
    /// quasi-static says [`crate::analysis::quasi_static`].
    pub mass_scaling: Real,
}

/// The standard experiment's mass scaling: none, the physical inertia.
/// **Why not more** (issue #8, BENCHMARKS.md): on B2 the work-precision
/// study found ×10 as accurate as ×1 at 3.2× fewer steps, but the inertia
/// raises σ_est of the softer, denser A3 by +0.45 / +1.1 / +2.4 % at
/// ×2 / ×4 / ×10 (a systematic shift, growing with F), which takes A3 out
/// of its 5 % agreement with CalculiX at ×10; the quasi-static certificate
/// (kinetic energy ~10⁻⁵ of the internal work) does not see it.
pub const STANDARD_MASS_SCALING: Real = 1.0;

/// The largest final platen strain x/d a scene accepts (0 < strain ≤ this).
pub const MAX_FINAL_STRAIN: Real = 0.9;
// Spelled out in the range of `PlatenParams::validate`.
const _: () = assert!(MAX_FINAL_STRAIN == 0.9);

impl PlatenParams {
    /// The standard experiment for `material`: ξ = 0.5, 5 mm/s, the
    /// material's friction, to 40 % strain, C = 0.9 on the global estimate
    /// 2/ω_max (power iteration every 1000 steps, tracked by the element
    /// lengths every 100 steps), samples every 0.5 % strain, no gravity,
    /// octant symmetry, masses ×[`STANDARD_MASS_SCALING`].
    pub fn standard(material: Material) -> Self {
        Self {
            material,
            elements: ElementSettings {
                kind: ElementKind::OnePoint,
                update: crate::constitutive::UpdateOptions::default(),
                hourglass_kappa: crate::element::force::DEFAULT_HOURGLASS_KAPPA,
            },
            damping_ratio: 0.5,
            approach_speed_m_s: 5.0e-3,
            friction: material.params.friction,
            final_strain: 0.4,
            time_step_safety: 0.9,
            time_step_interval: 100,
            time_step_method: TimeStepMethod::Global {
                power_interval: 10,
                power_iterations: 30,
            },
            output_strain_interval: 0.005,
            gravity_m_s2: 0.0,
            symmetry: Symmetry::Octant,
            mass_scaling: STANDARD_MASS_SCALING,
        }
    }

    fn validate(&self) -> Result<(), SceneError> {
        let (power_interval, power_iterations) = match self.time_step_method {
            TimeStepMethod::Element => (1, 1),
            TimeStepMethod::Global {
                power_interval,
                power_iterations,
            } => (power_interval, power_iterations),
        };
        let checks: [(bool, &'static str, Real, &'static str); 13] = [
            (
                power_interval >= 1,
                "power_interval",
                power_interval as Real,
                ">= 1",
            ),
            (
                (1..=1000).contains(&power_iterations),
                "power_iterations",
                power_iterations as Real,
                "1 ..= 1000",
            ),
            (
                (0.0..=2.0).contains(&self.damping_ratio),
                "damping_ratio",
                self.damping_ratio,
                "0 <= xi <= 2",
            ),
            (
                self.approach_speed_m_s > 0.0 && self.approach_speed_m_s <= 10.0,
                "approach_speed_m_s",
                self.approach_speed_m_s,
                "0 < v <= 10 m/s",
            ),
            (
                (0.0..=crate::material::MAX_FRICTION).contains(&self.friction),
                "friction",
                self.friction,
                crate::material::FRICTION_ALLOWED,
            ),
            (
                self.final_strain > 0.0 && self.final_strain <= MAX_FINAL_STRAIN,
                "final_strain",
                self.final_strain,
                "0 < strain <= 0.9",
            ),
            (
                self.time_step_safety > 0.0 && self.time_step_safety <= 1.0,
                "time_step_safety",
                self.time_step_safety,
                "0 < C <= 1",
            ),
            (
                self.time_step_interval >= 1,
                "time_step_interval",
                self.time_step_interval as Real,
                ">= 1",
            ),
            (
                self.output_strain_interval > 0.0
                    && self.output_strain_interval <= self.final_strain,
                "output_strain_interval",
                self.output_strain_interval,
                "0 < interval <= final_strain",
            ),
            (
                self.elements.hourglass_kappa >= 0.0 && self.elements.hourglass_kappa <= 1.0,
                "hourglass_kappa",
                self.elements.hourglass_kappa,
                "0 <= kappa <= 1",
            ),
            (
                self.elements.update.yield_tolerance_is_valid(),
                "yield_tolerance",
                self.elements.update.yield_tolerance,
                crate::granule::forces::YIELD_TOLERANCE_RANGE,
            ),
            (
                self.gravity_m_s2 >= 0.0
                    && self.gravity_m_s2 <= 1.0e3
                    && (self.symmetry == Symmetry::Full || self.gravity_m_s2 == 0.0),
                "gravity_m_s2",
                self.gravity_m_s2,
                "0 <= g <= 1000, and 0 with octant symmetry",
            ),
            (
                (1.0..=1.0e6).contains(&self.mass_scaling),
                "mass_scaling",
                self.mass_scaling,
                "1 <= F <= 1e6",
            ),
        ];
        for (ok, field, value, allowed) in checks {
            if !ok {
                return Err(SceneError::InvalidParameter {
                    field,
                    value,
                    allowed,
                });
            }
        }
        Ok(())
    }
}

/// Why the experiment cannot go on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneError {
    /// A parameter is out of range.
    InvalidParameter {
        /// Field of [`PlatenParams`].
        field: &'static str,
        /// Value given.
        value: Real,
        /// Allowed range.
        allowed: &'static str,
    },
    /// The mesh is not consistent ([`crate::mesh::octant::MeshView::check`]:
    /// more surface nodes than nodes, or a hex or quad naming a node it
    /// does not have).
    Mesh(MeshError),
    /// A buffer has the wrong length.
    BufferLength {
        /// Buffer name as in [`PlatenBuffers`].
        buffer: &'static str,
        /// Entries expected.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// An element failed (inverted, no convergence, …) at `step`.
    Element {
        /// Step number.
        step: u64,
        /// Strain reached.
        strain: Real,
        /// The element and its error (or, at step 0, a mesh whose hexes
        /// name nodes it does not have).
        failure: ForcesError,
    },
    /// A platen contact pass refused its input (a platen's normal or the
    /// step's Δt², which the scene's own checks should already have
    /// caught).
    Contact {
        /// Step number.
        step: u64,
        /// Strain reached.
        strain: Real,
        /// What the pass refused.
        error: ContactError,
    },
    /// The motion became non-finite, or an element inverted or folded so
    /// that the time step could not be estimated.
    Unstable {
        /// Step number.
        step: u64,
        /// Strain reached.
        strain: Real,
        /// The element with the smallest Gauss-point Jacobian ratio at
        /// that moment ([`worst_element`]): ≤ 0 where it folded or
        /// inverted, NaN where a node's position is not finite. `None` for
        /// a mesh without elements.
        worst: Option<WorstElement>,
    },
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParameter {
                field,
                value,
                allowed,
            } => write!(f, "invalid `{field}` = {value}: allowed range is {allowed}"),
            Self::Mesh(e) => write!(f, "the mesh: {e}"),
            Self::BufferLength {
                buffer,
                expected,
                got,
            } => write!(
                f,
                "buffer `{buffer}` has {got} entries, expected {expected}"
            ),
            Self::Element {
                step,
                strain,
                failure,
            } => write!(f, "step {step} (strain {strain:.4}): {failure}"),
            Self::Contact {
                step,
                strain,
                error,
            } => write!(
                f,
                "step {step} (strain {strain:.4}): platen contact: {error}"
            ),
            Self::Unstable {
                step,
                strain,
                worst,
            } => {
                write!(f, "step {step} (strain {strain:.4}): ")?;
                match worst {
                    Some(w) if w.ratio.is_nan() => write!(
                        f,
                        "the motion became non-finite (element {} has a node at a non-finite \
                         position)",
                        w.element
                    ),
                    Some(w) if w.ratio <= 0.0 => write!(
                        f,
                        "element {} folded or inverted (smallest Gauss-point Jacobian ratio \
                         {:.3e} <= 0)",
                        w.element, w.ratio
                    ),
                    Some(w) => write!(
                        f,
                        "the motion became unstable (no element inverted; the most distorted, \
                         element {}, has a Gauss-point Jacobian ratio of {:.3e})",
                        w.element, w.ratio
                    ),
                    None => write!(f, "the motion became non-finite"),
                }
            }
        }
    }
}

impl core::error::Error for SceneError {}

/// Caller-owned state of the experiment; all buffers are written by
/// [`PlatenScene::new`].
pub struct PlatenBuffers<'a> {
    /// The granule (see [`GranuleBuffers`]).
    pub granule: GranuleBuffers<'a>,
    /// Scratch of the global time-step estimate: node buffers one entry per
    /// node, `cp_scratch` as many as `granule.cp_inv`. Unused (and unchecked)
    /// with [`TimeStepMethod::Element`].
    pub power: PowerIterationBuffers<'a>,
}

/// The energy ledger of the whole granule (full-granule equivalent), J.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyLedger {
    /// Kinetic energy at the last half step.
    pub kinetic: Real,
    /// Work of the internal + hourglass forces (stored + dissipated).
    pub internal_work: Real,
    /// Stored elastic energy Σ V0 ψ (updated at samples).
    pub elastic: Real,
    /// Plastic dissipation Σ V0 Δγ(2β² + ⅔a1α²).
    pub plastic: Real,
    /// Hourglass energy (k/2)Σ|q|² at the last step.
    pub hourglass: Real,
    /// Energy removed by damping.
    pub damping: Real,
    /// Work of the platen contact forces on the nodes.
    pub contact_work: Real,
    /// Work of gravity.
    pub gravity_work: Real,
    /// Work of the platens: ∫ F·v_platen dt.
    pub platen_work: Real,
}

impl EnergyLedger {
    /// Residual of the balance W_gravity + W_contact = ΔKE + W_int + D_damp
    /// (physics.md §4.5; W_int includes the hourglass work), J. Every work
    /// term uses the same midpoint displacement ½(Δx_{n−½} + Δx_{n+½}), for
    /// which central differences balance exactly: the residual is round-off
    /// unless a force is missing from the books or the integration broke.
    pub fn residual(&self) -> Real {
        self.gravity_work + self.contact_work - (self.kinetic + self.internal_work + self.damping)
    }

    /// The return map's energy gap W_int − (Ψ + D_plastic + E_hg), J: how far
    /// the work done on the elements exceeds the stored elastic energy, the
    /// plastic dissipation Σ V0 Δγ(2β² + ⅔a1α²) and the hourglass energy.
    /// It measures the energy consistency of the constitutive algorithm
    /// (the published corrector is not exactly work-conjugate); about 1 % of
    /// the platen work for B2 with the volume fix, 3 % without.
    pub fn return_map_gap(&self) -> Real {
        self.internal_work - (self.elastic + self.plastic + self.hourglass)
    }
}

/// One output sample (full-granule equivalents).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlatenSample {
    /// Simulated time, s.
    pub time_s: Real,
    /// Platen approach x, m.
    pub approach_m: Real,
    /// x/d.
    pub strain: Real,
    /// Upper platen force, averaged over the sample interval, N.
    pub force_upper_n: Real,
    /// Lower platen force, averaged over the sample interval, N.
    pub force_lower_n: Real,
    /// Steps so far.
    pub steps: u64,
    /// Current time step, s.
    pub dt_s: Real,
    /// Smallest element J of the last step.
    pub min_j: Real,
    /// Smallest Gauss-point Jacobian ratio of any element at this instant
    /// (≤ 0: an element folded; see [`crate::granule::quality`]).
    pub min_gauss_jacobian: Real,
    /// Largest nodal speed |v_{n+½}| over the sample interval, m/s.
    pub max_node_speed_m_s: Real,
    /// Deepest overlap of a surface node with a platen at this instant
    /// (kinematic contact closes gaps exactly, so round-off unless contact
    /// failed), m; 0 if none.
    pub penetration_m: Real,
    /// Energies.
    pub energy: EnergyLedger,
}

/// The columns of a sample's table row, (name, meaning with its unit;
/// units in the names, energies whole-granule equivalents):
/// [`PlatenSample::values`], then `steps`. The CLI's
/// `force_displacement.csv` and its report's glossary, and the browser's
/// CSV and page, use them.
pub const SAMPLE_COLUMNS: [(&str, &str); 18] = [
    ("time_s", "simulated time, s"),
    (
        "displacement_m",
        "platen approach x (both platens together), m",
    ),
    ("strain", "x/d, d the granule's diameter"),
    ("force_n", "mean of the upper and lower platen forces, N"),
    (
        "force_upper_n",
        "upper platen force, averaged over the sample interval, N",
    ),
    (
        "force_lower_n",
        "lower platen force, N (the upper's in an octant run)",
    ),
    ("kinetic_j", "kinetic energy, J"),
    (
        "internal_work_j",
        "work of the internal and hourglass forces, J",
    ),
    ("elastic_j", "elastic energy Ψ, J"),
    ("plastic_j", "plastic dissipation, J"),
    (
        "hourglass_j",
        "energy in the one-point element's hourglass modes, J",
    ),
    ("damping_j", "energy removed by the damping, J"),
    (
        "contact_work_j",
        "work of the platen contacts on the nodes, J",
    ),
    ("gravity_work_j", "work of gravity, J"),
    ("platen_work_j", "work of the moving platens, J"),
    (
        "min_jacobian",
        "smallest element volume ratio J of the sample's last step",
    ),
    ("dt_s", "time step, s"),
    ("steps", "time steps so far"),
];

// Every column has a meaning (the glossaries show it), checked when the
// kernel compiles.
const _: () = {
    let mut i = 0;
    while i < SAMPLE_COLUMNS.len() {
        assert!(!SAMPLE_COLUMNS[i].1.is_empty());
        i += 1;
    }
};

/// σ_est of a run ([`PlatenSample::sigma_est`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmaEst {
    /// σ_est = 4/(πd)·dF/dx, Pa.
    pub sigma_pa: Real,
    /// The least-squares line F(x) behind it.
    pub fit: crate::analysis::fit::LineFit,
    /// x/d of the first and the last sample fitted.
    pub strain_range: [Real; 2],
}

impl PlatenSample {
    /// The platen force: the mean of the upper and lower platen forces, N
    /// (the table's `force_n`; the σ_est fit uses it too).
    pub fn mean_force(&self) -> Real {
        0.5 * (self.force_upper_n + self.force_lower_n)
    }

    /// σ_est of a run's `samples` (written every `interval` of strain) on a
    /// granule of diameter `diameter` (m): the fit of the mean platen force
    /// against the approach over [`crate::analysis::granule::fit_window`]
    /// (`yield_stress_estimate`), with the strains x/d of the first and the
    /// last sample it took. `None` with fewer than two samples there.
    pub fn sigma_est(samples: &[PlatenSample], diameter: Real, interval: Real) -> Option<SigmaEst> {
        use crate::analysis::granule::{fit_window, yield_stress_estimate};
        let [lo, hi] = fit_window(interval);
        let points = samples.iter().map(|s| (s.approach_m, s.mean_force()));
        let (sigma_pa, fit) = yield_stress_estimate(points, diameter, lo, hi)?;
        let strains = samples
            .iter()
            .map(|s| s.approach_m / diameter)
            .filter(|c| *c >= lo && *c <= hi);
        let first = strains.clone().next()?;
        let last = strains.clone().next_back()?;
        Some(SigmaEst {
            sigma_pa,
            fit,
            strain_range: [first, last],
        })
    }

    /// The quasi-static certificate of a run's `samples` (in time order;
    /// [`crate::analysis::quasi_static::judged`] picks the second half),
    /// with the rate check's change of the force curve if it ran.
    pub fn certificate(
        samples: &[PlatenSample],
        symmetry: Symmetry,
        rate_change_rel: Option<Real>,
    ) -> crate::analysis::quasi_static::Certificate {
        use crate::analysis::quasi_static::{certificate, judged};
        certificate(
            judged(samples).iter().map(|s| s.load_sample(symmetry)),
            rate_change_rel,
        )
    }

    /// The sample as the quasi-static certificate reads it: the upper
    /// platen drives, the lower one takes up — measured with
    /// [`Symmetry::Full`] only (an octant's lower platen is the mirror
    /// image of the upper one).
    pub fn load_sample(&self, symmetry: Symmetry) -> crate::analysis::quasi_static::LoadSample {
        crate::analysis::quasi_static::LoadSample {
            kinetic_j: self.energy.kinetic,
            internal_work_j: self.energy.internal_work,
            force_in_n: self.force_upper_n,
            force_out_n: (symmetry == Symmetry::Full).then_some(self.force_lower_n),
            // Between platens nothing is imposed but the platens themselves.
            kinetic_relative_j: None,
        }
    }

    /// The real-valued cells of the table row, in the order of
    /// [`SAMPLE_COLUMNS`] (all but the last, `steps` = [`Self::steps`]).
    pub fn values(&self) -> [Real; SAMPLE_COLUMNS.len() - 1] {
        let e = &self.energy;
        [
            self.time_s,
            self.approach_m,
            self.strain,
            self.mean_force(),
            self.force_upper_n,
            self.force_lower_n,
            e.kinetic,
            e.internal_work,
            e.elastic,
            e.plastic,
            e.hourglass,
            e.damping,
            e.contact_work,
            e.gravity_work,
            e.platen_work,
            self.min_j,
            self.dt_s,
        ]
    }
}

/// The running experiment.
pub struct PlatenScene<'a> {
    params: PlatenParams,
    mesh: ReferenceMesh<'a>,
    buf: GranuleBuffers<'a>,
    power: PowerIterationBuffers<'a>,
    time_step: TimeStepControl,
    diameter: Real,
    z_top0: Real,
    force_scale: Real,
    energy_scale: Real,
    /// The material as the inertia sees it: density ×`mass_scaling`
    /// (masses, damping, the element estimate's wave speed).
    inertia: Material,
    damping_c: Real,
    time: Real,
    step: u64,
    dt: Real,
    dt_prev: Real,
    min_j: Real,
    ledger: EnergyLedger,
    window_impulse: [Real; 2],
    window_time: Real,
    window_max_speed_squared: Real,
    next_output: Real,
    element_steps: u64,
}

/// The largest strain the platens may add in one step: a step of the
/// standard B2 granule at 5 mm/s adds about 10⁻⁵ (8.6e-6 on the 8x2 mesh,
/// 1.8e-5 on 4x1: the first `dt_s` of `granbed-cli granule`'s
/// `force_displacement.csv` × 5 mm/s / 1 mm).
pub const MAX_STRAIN_PER_STEP: Real = 1e-3;

/// The time step `dt` (s) limited so that the platens approach by at most
/// [`MAX_STRAIN_PER_STEP`] × the granule `diameter` (m) per step, i.e. it
/// binds where v·dt_stable > 1e-3 d. For B2's granule that is a platen
/// speed above about 0.6 m/s on the 8x2 mesh (0.3 m/s on 4x1), a mass
/// scaling above about 10⁴ at 5 mm/s, or E below 100–300 Pa: there the
/// runs take more steps than before the cap and their curves change.
/// Without it a granule so soft that its waves are slower than the
/// platens (E = 1e-3 Pa) went past its final strain in a single step,
/// with no curve between, and a 10 m/s platen moved 5 % of the diameter
/// per step.
fn capped_step(dt: Real, params: &PlatenParams, diameter: Real) -> Real {
    crate::math::min(
        dt,
        MAX_STRAIN_PER_STEP * diameter / params.approach_speed_m_s,
    )
}

fn check_len(buffer: &'static str, got: usize, expected: usize) -> Result<(), SceneError> {
    if got == expected {
        Ok(())
    } else {
        Err(SceneError::BufferLength {
            buffer,
            expected,
            got,
        })
    }
}

impl<'a> PlatenScene<'a> {
    /// Initialises the buffers (x = X, v = 0, C_p⁻¹ = 1, masses, symmetry
    /// mask) and the first time step.
    pub fn new(
        params: PlatenParams,
        mesh: ReferenceMesh<'a>,
        buf: PlatenBuffers<'a>,
    ) -> Result<Self, SceneError> {
        params.validate()?;
        let nodes = mesh.mesh.positions.len();
        let states = mesh.mesh.hexes.len() * params.elements.points_per_element();
        let PlatenBuffers {
            granule: buf,
            power,
        } = buf;
        let wrong_power = [
            ("mode", power.mode.len(), nodes),
            ("x_pert", power.x_pert.len(), nodes),
            ("f_plus", power.f_plus.len(), nodes),
            ("f_minus", power.f_minus.len(), nodes),
            ("cp_scratch", power.cp_scratch.len(), states),
        ]
        .into_iter()
        .find(|(_, got, expected)| {
            got != expected && params.time_step_method != TimeStepMethod::Element
        })
        .map(|(name, got, expected)| (name, expected, got));
        if let Some((buffer, expected, got)) = buf.wrong_length(nodes, states).or(wrong_power) {
            return Err(SceneError::BufferLength {
                buffer,
                expected,
                got,
            });
        }
        check_len("node_volume", mesh.node_volume.len(), nodes)?;
        // Its surface is the last `surface_nodes` nodes (the platens'
        // contact); the element check below covers the hexes' ids only.
        mesh.mesh.check().map_err(SceneError::Mesh)?;
        check_element_buffers(
            &mesh,
            params.elements.points_per_element(),
            nodes,
            states,
            None,
        )
        .map_err(|failure| match failure {
            ForcesError::BufferLength {
                buffer,
                expected,
                got,
            } => SceneError::BufferLength {
                buffer,
                expected,
                got,
            },
            failure => SceneError::Element {
                step: 0,
                strain: 0.0,
                failure,
            },
        })?;
        let mat = Material {
            density0: params.material.density0 * params.mass_scaling,
            ..params.material
        };
        let (mut buf, mut power) = (buf, power);
        buf.reset(&mesh, &mat);
        if params.symmetry == Symmetry::Octant {
            for (fixed, x) in buf.fixed.iter_mut().zip(mesh.mesh.positions) {
                for (a, c) in x.iter().enumerate() {
                    if *c == 0.0 {
                        *fixed |= 1 << a;
                    }
                }
            }
        }
        let z_top0 = mesh
            .mesh
            .positions
            .iter()
            .fold(Real::NEG_INFINITY, |m, x| crate::math::max(m, x[2]));
        let radius = z_top0;
        // Warm start of the power iteration: a fixed, non-symmetric field.
        power_start(power.mode);
        let mut time_step = TimeStepControl::new(params.time_step_method, params.time_step_safety);
        let at = Linearisation {
            mass: buf.mass,
            x: buf.x,
            cp_inv: buf.cp_inv,
        };
        let dt = time_step
            .estimate(&mesh, &mat, &params.elements, &at, &mut power)
            .map(|dt| capped_step(dt, &params, 2.0 * radius))
            .ok_or_else(|| SceneError::Unstable {
                step: 0,
                strain: 0.0,
                worst: worst_element(&mesh, buf.x),
            })?;
        let (force_scale, energy_scale) = if params.symmetry == Symmetry::Octant {
            (4.0, 8.0)
        } else {
            (1.0, 1.0)
        };
        Ok(Self {
            damping_c: damping_coefficient(params.damping_ratio, mat.mu, mat.density0, radius),
            inertia: mat,
            params,
            mesh,
            buf,
            power,
            time_step,
            diameter: 2.0 * radius,
            z_top0,
            force_scale,
            energy_scale,
            time: 0.0,
            step: 0,
            dt,
            dt_prev: dt,
            min_j: 1.0,
            ledger: EnergyLedger::default(),
            window_impulse: [0.0; 2],
            window_time: 0.0,
            window_max_speed_squared: 0.0,
            next_output: params.output_strain_interval,
            element_steps: 0,
        })
    }

    /// Platen approach at time `t`, m.
    fn approach_at(&self, t: Real) -> Real {
        self.params.approach_speed_m_s * t
    }

    /// Current strain x/d.
    pub fn strain(&self) -> Real {
        self.approach_at(self.time) / self.diameter
    }

    /// True once the final strain is reached.
    pub fn finished(&self) -> bool {
        self.strain() >= self.params.final_strain
    }

    /// Current node positions, m.
    pub fn positions(&self) -> &[[Real; 3]] {
        self.buf.x
    }

    /// Simulated time, s.
    pub fn time(&self) -> Real {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Element evaluations so far (steps × elements simulated).
    pub fn element_steps(&self) -> u64 {
        self.element_steps
    }

    /// The granule diameter d used for the strain, m.
    pub fn diameter(&self) -> Real {
        self.diameter
    }

    /// Current time step, s.
    pub fn time_step(&self) -> Real {
        self.dt
    }

    /// The parameters.
    pub fn params(&self) -> &PlatenParams {
        &self.params
    }

    /// Ends the experiment and hands the caller's buffers back (in the
    /// state the last step left them), so that a caller holding them for
    /// the program's lifetime — the browser front end — can lend them to
    /// the next run.
    pub fn into_buffers(self) -> PlatenBuffers<'a> {
        PlatenBuffers {
            granule: self.buf,
            power: self.power,
        }
    }

    /// The sample at the current instant, with the platen forces averaged
    /// over the window since the last sample (zero at t = 0). Updates the
    /// stored elastic energy.
    pub fn sample(&mut self) -> PlatenSample {
        self.ledger.elastic = self.energy_scale
            * elastic_energy(
                &self.mesh,
                &self.params.material,
                &self.params.elements,
                self.buf.x,
                self.buf.cp_inv,
            )
            // The buffers and the mesh were checked by `new`.
            .unwrap_or(Real::NAN);
        let avg = |impulse: Real| {
            if self.window_time > 0.0 {
                self.force_scale * impulse / self.window_time
            } else {
                0.0
            }
        };
        let force_upper_n = avg(self.window_impulse[0]);
        let force_lower_n = if self.params.symmetry == Symmetry::Octant {
            force_upper_n
        } else {
            avg(self.window_impulse[1])
        };
        let max_node_speed_m_s = math::sqrt(self.window_max_speed_squared);
        self.window_impulse = [0.0; 2];
        self.window_time = 0.0;
        self.window_max_speed_squared = 0.0;
        // Platens at this instant: the upper at z_top0 − x/2, the lower
        // (full sphere) mirrored.
        let z_top = self.z_top0 - 0.5 * self.approach_at(self.time);
        let full = self.params.symmetry == Symmetry::Full;
        let penetration_m =
            self.buf.x[self.mesh.first_surface_node()..]
                .iter()
                .fold(0.0, |d: Real, x| {
                    let below = if full { -z_top - x[2] } else { 0.0 };
                    math::max(d, math::max(x[2] - z_top, below))
                });
        PlatenSample {
            time_s: self.time,
            approach_m: self.approach_at(self.time),
            strain: self.strain(),
            force_upper_n,
            force_lower_n,
            steps: self.step,
            dt_s: self.dt,
            min_j: self.min_j,
            min_gauss_jacobian: worst_element(&self.mesh, self.buf.x)
                .map_or(Real::NAN, |w| w.ratio),
            max_node_speed_m_s,
            penetration_m,
            energy: self.ledger,
        }
    }

    /// The error of a step that went unstable at `strain`, naming the
    /// element that folded (or the first with a non-finite node).
    fn unstable(&self, strain: Real) -> SceneError {
        SceneError::Unstable {
            step: self.step,
            strain,
            worst: worst_element(&self.mesh, self.buf.x),
        }
    }

    /// Gravity on the scaled masses, m/s²: g/F keeps the weight.
    fn scaled_gravity(&self) -> Real {
        self.params.gravity_m_s2 / self.params.mass_scaling
    }

    /// Advances one step. Returns a sample when an output interval ends.
    pub fn step(&mut self) -> Result<Option<PlatenSample>, SceneError> {
        let strain = self.strain();
        if self.step > 0
            && self
                .step
                .is_multiple_of(u64::from(self.params.time_step_interval))
        {
            self.dt_prev = self.dt;
            let at = Linearisation {
                mass: self.buf.mass,
                x: self.buf.x,
                cp_inv: self.buf.cp_inv,
            };
            self.dt = self
                .time_step
                .estimate(
                    &self.mesh,
                    &self.inertia,
                    &self.params.elements,
                    &at,
                    &mut self.power,
                )
                .map(|dt| capped_step(dt, &self.params, self.diameter))
                .ok_or_else(|| self.unstable(strain))?;
        }
        let sizes = StepSizes {
            dt_prev: self.dt_prev,
            dt: self.dt,
        };
        let gravity = self.scaled_gravity();
        let loads = Loads {
            gravity_m_s2: gravity,
            damping_c: self.damping_c,
            rigid_modes: self.params.symmetry == Symmetry::Full,
            selective_mass_factor: 1.0,
        };
        let b = &mut self.buf;
        let summary = predict(
            &self.mesh,
            &self.params.material,
            &self.params.elements,
            b,
            sizes,
            &loads,
        )
        .map_err(|failure| SceneError::Element {
            step: self.step,
            strain,
            failure,
        })?;
        self.element_steps += self.mesh.mesh.hexes.len() as u64;
        self.min_j = summary.min_j;

        // Platen contact on the predicted configuration at t_{n+1}.
        let dt = sizes.dt;
        let half = 0.5 * self.params.approach_speed_m_s * (self.time + dt);
        let surface = self.mesh.first_surface_node()..b.x.len();
        let body = PredictedNodes {
            mass: b.mass,
            x_n: b.x,
            x_pred: b.x_pred,
            rigid_shift: RigidShift::NONE,
        };
        let upper = Plane {
            normal: [0.0, 0.0, -1.0],
            offset: -(self.z_top0 - half),
        };
        let friction = self.params.friction;
        let step = self.step;
        let contact_error = |error| SceneError::Contact {
            step,
            strain,
            error,
        };
        let top = plane_contact(
            &upper,
            friction,
            sizes.contact_dt_squared(),
            surface.clone(),
            &body,
            b.f_c,
        )
        .map_err(contact_error)?;
        let bottom = if self.params.symmetry == Symmetry::Full {
            let lower = Plane {
                normal: [0.0, 0.0, 1.0],
                offset: -self.z_top0 + half,
            };
            plane_contact(
                &lower,
                friction,
                sizes.contact_dt_squared(),
                surface,
                &body,
                b.f_c,
            )
            .map_err(contact_error)?
        } else {
            Default::default()
        };

        // The buffers and step sizes passed `predict`'s checks above.
        let w = correct(b, sizes, &loads).map_err(|failure| SceneError::Element {
            step: self.step,
            strain,
            failure,
        })?;
        self.window_max_speed_squared =
            math::max(self.window_max_speed_squared, w.max_speed_squared);
        let kinetic = w.kinetic;
        if !kinetic.is_finite() {
            return Err(self.unstable(strain));
        }
        let s = self.energy_scale;
        let l = &mut self.ledger;
        l.internal_work += s * w.internal;
        l.contact_work += s * w.contact;
        l.damping += s * w.damping;
        l.gravity_work += s * w.gravity;
        l.kinetic = s * kinetic;
        l.hourglass = s * summary.hourglass_energy;
        l.plastic += s * summary.plastic_dissipation;
        let speed = 0.5 * self.params.approach_speed_m_s;
        let (f_top, f_bottom) = if self.params.symmetry == Symmetry::Octant {
            (top.normal, top.normal)
        } else {
            (top.normal, bottom.normal)
        };
        l.platen_work += self.force_scale * (f_top + f_bottom) * speed * dt;
        self.window_impulse[0] += top.normal * dt;
        self.window_impulse[1] += bottom.normal * dt;
        self.window_time += dt;
        self.time += dt;
        self.step += 1;
        self.dt_prev = dt;
        if self.strain() + 1e-12 >= self.next_output || self.finished() {
            self.next_output += self.params.output_strain_interval;
            return Ok(Some(self.sample()));
        }
        Ok(None)
    }
}
