//! The stress update of one integration point: trial state, plastic
//! corrector, volume-drift correction, and the new stored state
//! (physics.md §1.2–§1.6).
//!
//! State per point is **C_p⁻¹ = F⁻¹ b^e F⁻ᵀ** (6 numbers, Voigt order,
//! dimensionless, initial value the identity). The trial tensor is
//! b^e,tr = F C_p⁻¹ Fᵀ, so elastic steps write nothing and superposed rigid
//! rotations leave the state unchanged.

use core::fmt;

use crate::constitutive::elastic;
use crate::constitutive::return_map::{ReturnMapSystem, ReturnMethod};
use crate::constitutive::yield_surface::{self, YieldCoefficients};
use crate::material::Material;
use crate::tensor::{self, Mat3, Voigt};
use crate::{Real, math};

/// Switches of the update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateOptions {
    /// Correct the volume drift of the published corrector (physics.md §1.6):
    /// after the return, set det b^e = (J^e)². `false` reproduces the
    /// published algorithm literally (spurious dilatation under shear).
    pub volume_fix: bool,
    /// A trial state with φ ≤ `yield_tolerance`·(2/3)a2σy² is elastic.
    pub yield_tolerance: Real,
}

impl Default for UpdateOptions {
    fn default() -> Self {
        Self {
            volume_fix: true,
            yield_tolerance: 1.0e-12,
        }
    }
}

/// What an update did; returned by value, never logged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateInfo {
    /// The step was plastic.
    pub plastic: bool,
    /// Solver that returned the stress ([`ReturnMethod::Elastic`] if none).
    pub method: ReturnMethod,
    /// Corrector iterations (0 for elastic steps and the radial return).
    pub iterations: u32,
    /// ε = (4/3)Δγ a1 α of the corrector (0 if elastic).
    pub eps: Real,
    /// δ = (4/3)Δγ θ of the corrector (0 if elastic).
    pub delta: Real,
    /// Plastic multiplier increment Δγ = 3δ/(4θ), 1/Pa.
    pub gamma: Real,
    /// Relative density η = η0/J at the end of the step.
    pub eta: Real,
    /// Elastic volume ratio J^e at the end of the step.
    pub je: Real,
    /// Yield-surface coefficients used.
    pub coefficients: YieldCoefficients,
    /// φ/((2/3)a2σy²) of the returned stress (trial value if elastic).
    pub residual: Real,
}

/// Why an update could not be done. The state is left unchanged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UpdateError {
    /// A component of F is NaN or infinite.
    NonFinite,
    /// J = det F ≤ 0, or so small that η0/J overflows: the element is
    /// inverted or crushed flat.
    InvertedDeformation {
        /// det F.
        j: Real,
    },
    /// det C_p⁻¹ ≤ 0 (or not finite): the stored state is corrupt.
    InvalidState {
        /// det C_p⁻¹.
        det: Real,
    },
    /// Neither Newton nor the bisection fallback reached the yield surface.
    NoConvergence {
        /// Best |φ|/((2/3)a2σy²) reached.
        residual: Real,
        /// Iterations spent.
        iterations: u32,
    },
}

impl fmt::Display for UpdateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite => f.write_str("deformation gradient is not finite"),
            Self::InvertedDeformation { j } => write!(f, "inverted element: det F = {j:e}"),
            Self::InvalidState { det } => write!(f, "invalid plastic state: det Cp^-1 = {det:e}"),
            Self::NoConvergence {
                residual,
                iterations,
            } => write!(
                f,
                "return map did not converge: |phi|/scale = {residual:e} after {iterations} iterations"
            ),
        }
    }
}

impl core::error::Error for UpdateError {}

/// Result of a successful update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointUpdate {
    /// Kirchhoff stress τ at the end of the step, Pa, Voigt order.
    pub tau: Voigt,
    /// Diagnostics.
    pub info: UpdateInfo,
}

impl PointUpdate {
    /// Plastic dissipation of the step per unit reference volume,
    /// Δγ τ:∂φ/∂τ = Δγ(2β² + ⅔ a1 α²), J/m³ (0 for elastic steps).
    pub fn dissipation_density(&self) -> Real {
        if !self.info.plastic {
            return 0.0;
        }
        let beta = tensor::norm(&tensor::deviator(&self.tau));
        let alpha = tensor::trace(&self.tau);
        self.info.gamma
            * (2.0 * beta * beta + (2.0 / 3.0) * self.info.coefficients.a1 * alpha * alpha)
    }
}

/// Updates one integration point to the end-of-step deformation gradient.
///
/// * `f_np1`: deformation gradient F_{n+1} (reference → current).
/// * `cp_inv`: in: C_p⁻¹ at the start of the step; out: at the end. Left
///   untouched on error and on elastic steps.
///
/// Returns the Kirchhoff stress and diagnostics, or an [`UpdateError`]; never
/// panics.
#[allow(non_snake_case)]
#[inline]
pub fn update_point(
    mat: &Material,
    opts: &UpdateOptions,
    f_np1: &Mat3,
    cp_inv: &mut Voigt,
) -> Result<PointUpdate, UpdateError> {
    let F = f_np1;
    if !F.iter().all(|x| x.is_finite()) {
        return Err(UpdateError::NonFinite);
    }
    let J = tensor::det_mat(F);
    if J.is_nan() || J <= 0.0 {
        return Err(UpdateError::InvertedDeformation { j: J });
    }
    let det_c = tensor::det(cp_inv);
    if det_c.is_nan() || det_c <= 0.0 || det_c.is_infinite() {
        return Err(UpdateError::InvalidState { det: det_c });
    }

    // Trial state (§1.3).
    let b_tr = tensor::push_forward(F, cp_inv);
    let je_tr = J * math::sqrt(det_c);
    let mu = mat.mu;
    let theta_tr = mu * tensor::trace(&b_tr);
    let s_tr = tensor::scale_add_identity(&tensor::deviator(&b_tr), mu, 0.0);
    let beta_tr = tensor::norm(&s_tr);
    let alpha_tr = theta_tr + elastic::h(mat, je_tr);
    let eta = mat.params.eta0 / J;
    if !eta.is_finite() {
        // J > 0 but so small (subnormal) that η = η0/J overflows: crushed
        // flat, for the update as good as inverted (found by fuzzing).
        return Err(UpdateError::InvertedDeformation { j: J });
    }
    let coefficients = yield_surface::coefficients(&mat.params, eta);
    let sy = mat.params.yield_stress_pa;
    let scale = yield_surface::yield_scale(&coefficients, sy);
    let phi_tr = yield_surface::yield_function(&coefficients, sy, beta_tr, alpha_tr);

    let mut info = UpdateInfo {
        plastic: false,
        method: ReturnMethod::Elastic,
        iterations: 0,
        eps: 0.0,
        delta: 0.0,
        gamma: 0.0,
        eta,
        je: je_tr,
        coefficients,
        residual: phi_tr / scale,
    };
    if phi_tr <= opts.yield_tolerance * scale {
        return Ok(PointUpdate {
            tau: elastic::kirchhoff(mat, &b_tr, je_tr),
            info,
        });
    }

    // Plastic corrector (§1.4).
    let system = ReturnMapSystem {
        theta_tr,
        je_tr,
        beta_tr,
        a1: coefficients.a1,
        yield_scale: scale,
        lambda: mat.lambda,
        mu,
    };
    let sol = system.solve().map_err(|best| UpdateError::NoConvergence {
        residual: math::abs(best.residual),
        iterations: best.iterations,
    })?;
    let theta = system.theta(sol.eps);
    let je = system.je(sol.eps);
    let alpha = system.alpha(sol.eps);
    let beta = system.beta(sol.eps, sol.delta);
    // Unit deviatoric direction, frozen at its trial value (n = 0 if βtr = 0).
    let n = if beta_tr > 0.0 {
        tensor::scale_add_identity(&s_tr, 1.0 / beta_tr, 0.0)
    } else {
        [0.0; 6]
    };
    let tau = tensor::scale_add_identity(&n, beta, alpha / 3.0);

    // New elastic left Cauchy–Green tensor b^e = k n + s 1 (§1.4, §1.6).
    let k = beta / mu;
    let s = if opts.volume_fix {
        spherical_part_for_volume(k, tensor::det(&n), je, theta / (3.0 * mu))
    } else {
        theta / (3.0 * mu)
    };
    let be = tensor::scale_add_identity(&n, k, s);
    let f_inv = tensor::inverse_with_det(F, J);
    let cp_new = tensor::push_forward(&f_inv, &be);
    if !cp_new.iter().all(|x| x.is_finite()) {
        return Err(UpdateError::NonFinite);
    }
    *cp_inv = cp_new;

    info.plastic = true;
    info.method = sol.method;
    info.iterations = sol.iterations;
    info.eps = sol.eps;
    info.delta = sol.delta;
    info.gamma = 3.0 * sol.delta / (4.0 * theta);
    info.je = je;
    info.residual = sol.residual;
    Ok(PointUpdate { tau, info })
}

/// The spherical coefficient `s` of b^e = k n + s 1 with det b^e = (J^e)²,
/// where `n` is a unit deviator with determinant `det_n` (physics.md §1.6):
/// the root of s³ − (k²/2)s + k³ det n − (J^e)² = 0 reached by Newton from
/// `s0`. For k = 0 the root is (J^e)^{2/3}.
pub fn spherical_part_for_volume(k: Real, det_n: Real, je: Real, s0: Real) -> Real {
    let target = je * je;
    if k == 0.0 {
        return math::cbrt(target);
    }
    let c1 = 0.5 * k * k;
    let c0 = k * k * k * det_n - target;
    let mut s = s0;
    for _ in 0..20 {
        let f = s * s * s - c1 * s + c0;
        let df = 3.0 * s * s - c1;
        let ds = f / df;
        if !ds.is_finite() {
            break;
        }
        s -= ds;
        if math::abs(ds) <= 1.0e-16 * math::abs(s) {
            break;
        }
    }
    s
}
