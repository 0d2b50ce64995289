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
use crate::constitutive::return_map::{ReturnMapSystem, ReturnMethod, ReturnSolution};
use crate::constitutive::yield_surface::{self, YieldCoefficients};
use crate::lanes::{Num, lane_bit};
use crate::material::Material;
use crate::tensor::{self, Mat3, Rows, Voigt};
use crate::{Real, math};

/// Switches of the update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateOptions {
    /// Correct the volume drift of the published corrector (physics.md §1.6):
    /// after the return, set det b^e = (J^e)². `false` reproduces the
    /// published algorithm literally (spurious dilatation under shear).
    pub volume_fix: bool,
    /// A trial state with φ ≤ `yield_tolerance`·(2/3)a2σy² is elastic
    /// (dimensionless, 0 ≤ tolerance ≤ [`MAX_YIELD_TOLERANCE`]). Not
    /// checked per point; the element passes and scenes check it once
    /// ([`UpdateOptions::yield_tolerance_is_valid`]). A negative or NaN
    /// tolerance sends admissible states to the corrector, which then
    /// reports [`UpdateError::NoConvergence`].
    pub yield_tolerance: Real,
}

/// The largest [`UpdateOptions::yield_tolerance`] accepted: the corrector's
/// fallback accepts a residual up to [`super::return_map::FALLBACK_RESIDUAL_MAX`],
/// and a looser elastic test would let states that much outside the yield
/// surface pass as elastic.
pub const MAX_YIELD_TOLERANCE: Real = 1.0e-6;

impl UpdateOptions {
    /// Whether `yield_tolerance` lies in 0 ≤ tolerance ≤
    /// [`MAX_YIELD_TOLERANCE`] (NaN does not).
    pub fn yield_tolerance_is_valid(&self) -> bool {
        (0.0..=MAX_YIELD_TOLERANCE).contains(&self.yield_tolerance)
    }
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

impl UpdateInfo {
    /// The diagnostics of an elastic step: relative density `eta`, elastic
    /// volume ratio `je`, the yield coefficients and φ/((2/3)a2σy²).
    pub const fn elastic(
        eta: Real,
        je: Real,
        coefficients: YieldCoefficients,
        residual: Real,
    ) -> Self {
        Self {
            plastic: false,
            method: ReturnMethod::Elastic,
            iterations: 0,
            eps: 0.0,
            delta: 0.0,
            gamma: 0.0,
            eta,
            je,
            coefficients,
            residual,
        }
    }

    /// Records the corrector's solution `sol` of a returned step, with
    /// the plastic multiplier increment `gamma` ([`Returned::gamma`]) and
    /// J^e(ε) `je` of the returned state.
    #[inline(always)]
    pub fn record_return(&mut self, sol: &ReturnSolution, gamma: Real, je: Real) {
        self.plastic = true;
        self.method = sol.method;
        self.iterations = sol.iterations;
        self.eps = sol.eps;
        self.delta = sol.delta;
        self.gamma = gamma;
        self.je = je;
        self.residual = sol.residual;
    }
}

/// Why an update could not be done. The state is left unchanged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UpdateError {
    /// A component of F is NaN or infinite, or F is so large that the
    /// trial stress it gives overflows (b = F C_p⁻¹ Fᵀ beyond the largest
    /// float).
    NonFinite,
    /// J = det F ≤ 0, or so small that η0/J overflows: the element is
    /// inverted or crushed flat.
    InvertedDeformation {
        /// det F.
        j: Real,
    },
    /// The stored state C_p⁻¹ is corrupt: its determinant is not in
    /// (0, ∞), or ([`check_state`]) it is not positive definite.
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
            Self::NonFinite => f.write_str(
                "deformation gradient is not finite, or so large that its trial stress overflows",
            ),
            Self::InvertedDeformation { j } => write!(f, "inverted element: det F = {j:e}"),
            Self::InvalidState { det } => write!(
                f,
                "invalid plastic state: Cp^-1 is not positive definite with a finite determinant \
                 (det Cp^-1 = {det:e})"
            ),
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
    /// Kirchhoff stress τ at the end of the step, Pa, Voigt order
    /// `[xx, yy, zz, yz, xz, xy]`, positive in tension (the pressure
    /// [`crate::tensor::pressure`] is positive in compression).
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
        dissipation_density(&self.tau, self.info.gamma, self.info.coefficients.a1)
    }
}

/// Δγ(2β² + ⅔ a1 α²), J/m³, of a returned stress `tau` (Pa) with plastic
/// multiplier increment `gamma` (1/Pa) and yield coefficient `a1`, over any
/// [`Num`] ([`PointUpdate::dissipation_density`] of a plastic step).
#[inline(always)]
pub fn dissipation_density<T: Num>(tau: &[T; 6], gamma: T, a1: T) -> T {
    let beta = tensor::norm(&tensor::deviator(tau));
    let alpha = tensor::trace(tau);
    gamma * (T::splat(2.0) * beta * beta + T::splat(2.0 / 3.0) * a1 * alpha * alpha)
}

/// The elastic trial state of a point (physics.md §1.3), over any [`Num`]
/// (one point, or one point per lane of an element batch). Computed for
/// any input; [`check_trial`] decides whether it is valid, elastic or
/// plastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trial<T> {
    /// J = det F.
    pub j: T,
    /// det C_p⁻¹ of the stored state.
    pub det_cp_inv: T,
    /// b^e,tr = F C_p⁻¹ Fᵀ (Voigt).
    pub b: [T; 6],
    /// J^e,tr = J √det C_p⁻¹.
    pub je: T,
    /// θtr = μ tr b^e,tr, Pa.
    pub theta: T,
    /// dev τtr = μ dev b^e,tr, Pa (Voigt).
    pub s: [T; 6],
    /// βtr = ‖dev τtr‖, Pa.
    pub beta: T,
    /// αtr = tr τtr = θtr + h(J^e,tr), Pa.
    pub alpha: T,
    /// Relative density η = η0/J.
    pub eta: T,
}

/// The trial state at deformation gradient `f` (rows) from the stored
/// state `cp_inv` = C_p⁻¹.
#[allow(non_snake_case)]
#[inline(always)]
pub fn trial<T: Num>(mat: &Material, f: &Rows<T>, cp_inv: &[T; 6]) -> Trial<T> {
    let J = tensor::det_rows(f);
    let det_cp_inv = tensor::det(cp_inv);
    let b = tensor::push_forward_rows(f, cp_inv);
    let je = J * det_cp_inv.sqrt();
    let mu = T::splat(mat.mu);
    let theta = mu * tensor::trace(&b);
    let s = tensor::scale_add_identity(&tensor::deviator(&b), mu, T::splat(0.0));
    let beta = tensor::norm(&s);
    let alpha = theta + elastic::h_lame(T::splat(mat.lambda), mu, je);
    Trial {
        j: J,
        det_cp_inv,
        b,
        je,
        theta,
        s,
        beta,
        alpha,
        eta: T::splat(mat.params.eta0) / J,
    }
}

/// What [`check_trial`] found for an admissible input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrialCheck {
    /// The diagnostics of an elastic step (η, J^e,tr, coefficients, φtr).
    pub info: UpdateInfo,
    /// `Some((2/3)a2σy²)` if the trial state violates the yield condition
    /// and the plastic corrector ([`plastic_return`]) must run.
    pub plastic_scale: Option<Real>,
}

/// Checks the input of an update: a finite `f`, J > 0, a valid stored state,
/// a finite η and a trial stress that does not overflow ([`check_input`]);
/// returns the yield function at the trial state with the diagnostics.
#[inline(always)]
pub fn check_trial(
    mat: &Material,
    opts: &UpdateOptions,
    f: &Rows<Real>,
    t: &Trial<Real>,
) -> Result<TrialCheck, UpdateError> {
    let coefficients = yield_surface::coefficients(&mat.params, t.eta);
    let sy = mat.params.yield_stress_pa;
    let scale = yield_surface::yield_scale(&coefficients, sy);
    let phi_tr = yield_surface::yield_function(&coefficients, sy, t.beta, t.alpha);
    check_input(f.iter().flatten().all(|x| x.is_finite()), t, phi_tr)?;
    Ok(TrialCheck {
        info: UpdateInfo::elastic(t.eta, t.je, coefficients, phi_tr / scale),
        plastic_scale: yields(opts, phi_tr, scale).then_some(scale),
    })
}

/// The input checks of [`check_trial`]: [`input_is_valid`] and a trial
/// yield function `phi_tr` below +∞ (−∞ is the elastic limit of an
/// infinite yield stress), and if not, the first test that failed, in this
/// order: F not finite
/// ([`UpdateError::NonFinite`]), J not > 0 (inverted), det C_p⁻¹ not in
/// (0, ∞) (invalid state), η not finite (inverted: J > 0 but so small —
/// subnormal — that η = η0/J overflows, crushed flat; found by fuzzing),
/// the trial yield function `phi_tr` +∞ or NaN (non-finite: a finite F so
/// large that F C_p⁻¹ Fᵀ or the stress's square overflows, which had read
/// as "no convergence" of a return map that could not start).
#[inline(always)]
pub fn check_input(f_finite: bool, t: &Trial<Real>, phi_tr: Real) -> Result<(), UpdateError> {
    let det_c = t.det_cp_inv;
    if input_is_valid(f_finite, t.j, det_c, t.eta) & (phi_tr < Real::INFINITY) {
        return Ok(());
    }
    Err(if !f_finite {
        UpdateError::NonFinite
    } else if t.j.is_nan() || t.j <= 0.0 {
        UpdateError::InvertedDeformation { j: t.j }
    } else if det_c.is_nan() || det_c <= 0.0 || det_c.is_infinite() {
        UpdateError::InvalidState { det: det_c }
    } else if !t.eta.is_finite() {
        UpdateError::InvertedDeformation { j: t.j }
    } else {
        UpdateError::NonFinite
    })
}

/// Whether an update's input is admissible: F finite (`f_finite`), J > 0,
/// 0 < det C_p⁻¹ < ∞ and η finite (a NaN fails every test) — the rule of
/// [`check_input`] without naming what failed, and without its test of
/// the trial yield function. The tests are combined without branches, so
/// an element batch takes one verdict for all its lanes (a batch that
/// fails is redone element by element, which names the error). The batch
/// needs no test of φ^tr: a φ^tr that is +∞ or NaN yields ([`yields`]),
/// the corrector cannot return it (or its state is not finite), and the
/// batch is redone element by element, where [`check_input`] names it.
#[inline(always)]
pub fn input_is_valid(f_finite: bool, j: Real, det_cp_inv: Real, eta: Real) -> bool {
    f_finite & (j > 0.0) & (det_cp_inv > 0.0) & (det_cp_inv < Real::INFINITY) & eta.is_finite()
}

/// Checks a stored state C_p⁻¹ supplied from outside the kernel: it must
/// be symmetric positive definite (its leading minors C11, C11 C22 − C12²
/// and det C_p⁻¹ all > 0, Sylvester's criterion) with a finite
/// determinant; [`UpdateError::InvalidState`] otherwise (a NaN entry
/// fails).
///
/// [`update_point`] and [`update_point_rows`] (hence the F-bar element's
/// points) check their state with it. The one-point element's paths test
/// only the determinant per element ([`check_input`]): the kernel's own
/// returns leave C_p⁻¹ = F⁻¹ b^e F⁻ᵀ positive definite, and the full test
/// cost the element loop about 1 % of its instructions (BENCHMARKS.md,
/// session 45), so a host that loads states from elsewhere checks them
/// once with this (the C ABI does, per element). A state with a positive determinant but two negative
/// eigenvalues had passed the determinant's test (an embedding audit).
pub fn check_state(cp_inv: &Voigt) -> Result<(), UpdateError> {
    let det = tensor::det(cp_inv);
    // Voigt [xx, yy, zz, yz, xz, xy]: C12 is entry 5.
    let minor2 = cp_inv[0] * cp_inv[1] - cp_inv[5] * cp_inv[5];
    let definite = cp_inv[0] > 0.0 && minor2 > 0.0 && det > 0.0 && det < Real::INFINITY;
    if definite {
        Ok(())
    } else {
        Err(UpdateError::InvalidState { det })
    }
}

/// Whether a trial state with yield function `phi_tr` and scale
/// (2/3)a2σy² `scale` yields: not `φ ≤ tol·scale`. Not `φ > tol·scale`: a
/// NaN φ (overflowed trial state) must go to the corrector, which reports
/// it, never pass as elastic (fuzzing).
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the test
pub fn yields(opts: &UpdateOptions, phi_tr: Real, scale: Real) -> bool {
    !(phi_tr <= opts.yield_tolerance * scale)
}

/// Updates one integration point to the end-of-step deformation gradient.
///
/// * `f_np1`: deformation gradient F_{n+1} (reference → current), an
///   nalgebra matrix ([`crate::nalgebra`], the kernel's own version); as
///   plain rows `[[F11, F12, F13], …]`, [`update_point_rows`].
/// * `cp_inv`: in: C_p⁻¹ at the start of the step (Voigt
///   `[xx, yy, zz, yz, xz, xy]`, symmetric positive definite: the identity
///   for a virgin point; [`check_state`]); out: at the end. Left untouched
///   on error and on elastic steps.
///
/// Returns the Kirchhoff stress and diagnostics, or an [`UpdateError`]; never
/// panics.
#[inline]
pub fn update_point(
    mat: &Material,
    opts: &UpdateOptions,
    f_np1: &Mat3,
    cp_inv: &mut Voigt,
) -> Result<PointUpdate, UpdateError> {
    update_point_rows(mat, opts, &tensor::rows(f_np1), cp_inv)
}

/// [`update_point`] with F given as rows.
#[inline]
pub fn update_point_rows(
    mat: &Material,
    opts: &UpdateOptions,
    f: &Rows<Real>,
    cp_inv: &mut Voigt,
) -> Result<PointUpdate, UpdateError> {
    check_state(cp_inv)?;
    update_checked_state(mat, opts, f, cp_inv)
}

/// [`update_point_rows`] without [`check_state`]: the update of an element
/// ([`crate::element::force::hex_forces`]), whose state only the
/// determinant's test of [`check_input`] checks, as the element batch
/// does, so that every element path refuses the same states.
#[inline]
pub(crate) fn update_checked_state(
    mat: &Material,
    opts: &UpdateOptions,
    f: &Rows<Real>,
    cp_inv: &mut Voigt,
) -> Result<PointUpdate, UpdateError> {
    let t = trial(mat, f, cp_inv);
    let check = check_trial(mat, opts, f, &t)?;
    match check.plastic_scale {
        None => Ok(PointUpdate {
            tau: elastic::kirchhoff(mat, &t.b, t.je),
            info: check.info,
        }),
        Some(scale) => {
            let (up, cp_new) = plastic_return(mat, opts, f, &t, check.info, scale)?;
            *cp_inv = cp_new;
            Ok(up)
        }
    }
}

/// The plastic corrector (physics.md §1.4, §1.6) of a trial state that
/// violates the yield condition: the stress and the new C_p⁻¹. `info` and
/// `scale` are [`check_trial`]'s.
#[allow(non_snake_case)]
pub fn plastic_return(
    mat: &Material,
    opts: &UpdateOptions,
    F: &Rows<Real>,
    t: &Trial<Real>,
    mut info: UpdateInfo,
    scale: Real,
) -> Result<(PointUpdate, Voigt), UpdateError> {
    let system = corrector(mat, t, info.coefficients.a1, scale);
    let sol = system.solve().map_err(|best| UpdateError::NoConvergence {
        residual: math::abs(best.residual),
        iterations: best.iterations,
    })?;
    let r = returned_state(mat, opts, F, t, &system, sol.eps, sol.delta, |_| true);
    if !r.cp_inv.iter().all(|x| x.is_finite()) {
        return Err(UpdateError::NonFinite);
    }
    info.record_return(&sol, r.gamma, r.je);
    Ok((PointUpdate { tau: r.tau, info }, r.cp_inv))
}

/// The corrector's system for a trial state `t` with yield coefficient
/// `a1` and scale (2/3)a2σy² `scale`, over any [`Num`].
#[inline(always)]
pub fn corrector<T: Num>(mat: &Material, t: &Trial<T>, a1: T, scale: T) -> ReturnMapSystem<T> {
    ReturnMapSystem {
        theta_tr: t.theta,
        je_tr: t.je,
        beta_tr: t.beta,
        a1,
        yield_scale: scale,
        lambda: T::splat(mat.lambda),
        mu: T::splat(mat.mu),
    }
}

/// The state on the yield surface at the corrector's solution (ε, δ):
/// what [`returned_state`] gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Returned<T> {
    /// Kirchhoff stress τ = β n + (α/3) 1, Pa (Voigt).
    pub tau: [T; 6],
    /// The new C_p⁻¹ = F⁻¹ b^e F⁻ᵀ (Voigt); the caller checks it is finite.
    pub cp_inv: [T; 6],
    /// θ(ε), Pa.
    pub theta: T,
    /// J^e(ε).
    pub je: T,
    /// The plastic multiplier increment Δγ = 3δ/(4θ(ε)), 1/Pa.
    pub gamma: T,
}

/// The returned stress and state at the corrector's solution (`eps`,
/// `delta`) of `system` (physics.md §1.4, §1.6), over any [`Num`]: one
/// point, or the lanes of an element batch at once with the scalar bits.
/// `returns(l)` says whether lane l is returned at all: only those solve
/// the volume fix's cubic (a lane that is not is computed at ε = δ = 0
/// by the batch and discarded).
#[allow(non_snake_case, clippy::too_many_arguments)]
#[inline(always)]
pub fn returned_state<T: Num>(
    mat: &Material,
    opts: &UpdateOptions,
    F: &Rows<T>,
    t: &Trial<T>,
    system: &ReturnMapSystem<T>,
    eps: T,
    delta: T,
    returns: impl Fn(usize) -> bool,
) -> Returned<T> {
    // 1/μ does not wait for the corrector, so the divisions by μ below
    // become multiplications off the chain of dependent divisions that
    // bounds this function (the Newton's, then the cubic's).
    let inv_mu = 1.0 / mat.mu;
    let theta = system.theta(eps);
    let je = system.je(eps);
    let alpha = system.alpha(eps);
    let beta = system.beta(eps, delta);
    // Unit deviatoric direction, frozen at its trial value (n = 0 if βtr = 0).
    // A loop, not the array's `map`, which rustc called out of line
    // (`core::array::try_map`, with the lanes passed through memory).
    let mut n = tensor::scale_add_identity(&t.s, T::splat(1.0) / t.beta, T::splat(0.0));
    for c in &mut n {
        *c = T::from_fn(|l| if t.beta.lane(l) > 0.0 { c.lane(l) } else { 0.0 });
    }
    let tau = tensor::scale_add_identity(&n, beta, alpha / T::splat(3.0));

    // New elastic left Cauchy–Green tensor b^e = k n + s 1 (§1.4, §1.6).
    let k = beta * T::splat(inv_mu);
    let s_literal = theta * T::splat(inv_mu / 3.0);
    let s = if opts.volume_fix {
        spherical_part_for_volume_in(k, tensor::det(&n), je, s_literal, returns)
    } else {
        s_literal
    };
    let be = tensor::scale_add_identity(&n, k, s);
    let f_inv = tensor::inverse_rows_with_det(F, t.j);
    Returned {
        tau,
        cp_inv: tensor::push_forward_rows(&f_inv, &be),
        theta,
        je,
        gamma: T::splat(3.0) * delta / (T::splat(4.0) * theta),
    }
}

/// The spherical coefficient `s` of b^e = k n + s 1 with det b^e = (J^e)²,
/// where `n` is a unit deviator with determinant `det_n` (physics.md §1.6):
/// the root of f(s) = s³ − (k²/2)s + k³ det n − (J^e)² = 0 reached by Newton
/// from `s0`. For k = 0 the root is (J^e)^{2/3}.
///
/// Newton stops after the step Δs whose successor it predicts below
/// 10⁻¹⁶|s|: the error left after a step is |f''/(2f')| Δs² =
/// 3|s| Δs²/|f'|, so the test is 3Δs² ≤ 10⁻¹⁶|f'| (no division). The
/// earlier test |Δs| ≤ 10⁻¹⁶|s| lay below one ulp of s ≈ 1, so it needed a
/// step of exactly zero: every call ran one step of round-off more, and
/// 0.7 % ran all 20 (BENCHMARKS.md, session 24).
pub fn spherical_part_for_volume(k: Real, det_n: Real, je: Real, s0: Real) -> Real {
    spherical_part_for_volume_in(k, det_n, je, s0, |_| true)
}

/// [`spherical_part_for_volume`] over any [`Num`], for the lanes `l` with
/// `solve(l)` (the others keep `s0`): every lane takes the scalar
/// function's Newton steps and stops where it stops, so it gets its bits.
/// The steps run for all lanes at once while any lane is still iterating;
/// a lane that has stopped keeps its value (at most 64 lanes).
#[inline(always)]
pub fn spherical_part_for_volume_in<T: Num>(
    k: T,
    det_n: T,
    je: T,
    s0: T,
    solve: impl Fn(usize) -> bool,
) -> T {
    let target = je * je;
    let c1 = T::splat(0.5) * k * k;
    let c0 = k * k * k * det_n - target;
    let mut s = s0;
    // Lane l iterates while bit l is set; k = 0 is closed-form.
    // One bit per lane: checked when the function is instantiated.
    const { assert!(T::LANES <= 64, "at most 64 lanes") };
    let mut iterating: u64 = 0;
    for l in 0..T::LANES {
        iterating |= u64::from(solve(l) && k.lane(l) != 0.0) << l;
    }
    for _ in 0..VOLUME_NEWTON_ITERATIONS {
        if iterating == 0 {
            break;
        }
        let f = s * s * s - c1 * s + c0;
        let df = T::splat(3.0) * s * s - c1;
        let ds = f / df;
        let stepped = s - ds;
        let mut next = iterating;
        // Per lane without early returns (fewer instructions in the batch:
        // BENCHMARKS.md, session 35): a step that is not finite stops the
        // lane untaken; the step predicted below round-off is the last.
        s = T::from_fn(|l| {
            let (ds, df) = (ds.lane(l), df.lane(l));
            let live = lane_bit(iterating, l);
            let finite = ds.is_finite();
            if live & (!finite | (3.0 * ds * ds <= 1.0e-16 * math::abs(df))) {
                next &= !(1 << l);
            }
            if live & finite {
                stepped.lane(l)
            } else {
                s.lane(l)
            }
        });
        iterating = next;
    }
    T::from_fn(|l| {
        if solve(l) && k.lane(l) == 0.0 {
            math::cbrt(target.lane(l))
        } else {
            s.lane(l)
        }
    })
}

/// Newton steps of [`spherical_part_for_volume`] at most.
const VOLUME_NEWTON_ITERATIONS: u32 = 20;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::Lanes;
    use crate::material::GranuleType;
    use crate::tensor::VOIGT_IDENTITY;

    /// A state from outside must be positive definite with a finite
    /// determinant: the point update refuses one with a positive
    /// determinant but two negative eigenvalues, one whose 2×2 leading
    /// minor is negative, one with a NaN or an infinite determinant, and
    /// leaves it untouched; the identity and a sheared positive definite
    /// state pass. The element's own test is the determinant alone
    /// ([`check_input`]), which the first two pass.
    /// A finite F so large that the trial state overflows is refused as
    /// non-finite, the state untouched: b = F C_p⁻¹ Fᵀ itself (F11 = 1e160,
    /// b11 = 1e320; J = 1e160 and η are finite), or the stress's norm and
    /// the yield function, which square it (F11 = 1e100, b finite). Both had
    /// gone on to the return map and read as "no convergence". (A finite
    /// trial state far outside any physical step, F11 = 1e20, still gives
    /// "no convergence"; a 100 % stretch in one step, F11 = 2, is returned.)
    #[test]
    fn a_trial_state_that_overflows_is_non_finite() {
        let mat = GranuleType::B2.params().validate().unwrap();
        let opts = UpdateOptions::default();
        let stretch = |s: Real| [[s, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let t = trial(&mat, &stretch(1e160), &VOIGT_IDENTITY);
        assert!(t.j.is_finite() && t.eta.is_finite() && !t.alpha.is_finite());
        let t = trial(&mat, &stretch(1e100), &VOIGT_IDENTITY);
        assert!(t.b.iter().all(|v| v.is_finite()) && !t.beta.is_finite());
        for s in [1e160, 1e100] {
            let mut c = VOIGT_IDENTITY;
            assert_eq!(
                update_point_rows(&mat, &opts, &stretch(s), &mut c),
                Err(UpdateError::NonFinite),
                "F11 = {s:e}"
            );
            assert_eq!(c, VOIGT_IDENTITY);
        }
        let mut c = VOIGT_IDENTITY;
        let r = update_point_rows(&mat, &opts, &stretch(2.0), &mut c);
        assert!(r.is_ok_and(|up| up.info.plastic), "{r:?}");
    }

    #[test]
    fn a_state_that_is_not_positive_definite_is_refused() {
        let mat = GranuleType::B2.params().validate().unwrap();
        let opts = UpdateOptions::default();
        let f = [[0.99, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for bad in [
            [-1.0, -1.0, 1.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, -3.0, 0.0, 0.0, 2.0],
            [1.0, 1.0, Real::NAN, 0.0, 0.0, 0.0],
            [1.0, 1.0, Real::INFINITY, 0.0, 0.0, 0.0],
        ] {
            assert!(
                matches!(check_state(&bad), Err(UpdateError::InvalidState { .. })),
                "{bad:?}"
            );
            let mut c = bad;
            let e = update_point_rows(&mat, &opts, &f, &mut c).unwrap_err();
            assert!(
                matches!(e, UpdateError::InvalidState { .. }),
                "{bad:?}: {e}"
            );
            assert_eq!(c.map(Real::to_bits), bad.map(Real::to_bits));
        }
        for bad in [
            [-1.0, -1.0, 1.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, -3.0, 0.0, 0.0, 2.0],
        ] {
            let t = trial(&mat, &f, &bad);
            assert!(
                t.det_cp_inv > 0.0 && check_input(true, &t, 0.0).is_ok(),
                "{bad:?}"
            );
        }
        for good in [VOIGT_IDENTITY, [1.2, 0.9, 1.0, 0.05, -0.1, 0.2]] {
            assert_eq!(check_state(&good), Ok(()));
            let mut c = good;
            update_point_rows(&mat, &opts, &f, &mut c).unwrap();
        }
    }

    /// [`returned_state`] over lanes gives every returned lane the bits of
    /// the scalar [`plastic_return`] (as the element batch uses it), with
    /// and without the volume fix: a lane under shear and compression, a
    /// hydrostatic lane whose βtr is exactly 0 (n = 0 by the lane select,
    /// where 1/βtr = ∞), an elastic lane computed at ε = δ = 0 and dropped,
    /// and a lane with a stored plastic state.
    #[test]
    fn returned_lanes_have_the_scalar_bits() {
        let mat = GranuleType::B2.params().validate().unwrap();
        let points: [(Rows<Real>, Voigt); 4] = [
            (
                [[0.97, 0.04, 0.0], [0.01, 0.93, 0.02], [0.0, -0.03, 0.9]],
                VOIGT_IDENTITY,
            ),
            (
                [[0.95, 0.0, 0.0], [0.0, 0.95, 0.0], [0.0, 0.0, 0.95]],
                VOIGT_IDENTITY,
            ),
            (
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                VOIGT_IDENTITY,
            ),
            (
                [[0.92, 0.0, 0.05], [0.0, 1.01, 0.0], [-0.02, 0.0, 0.94]],
                [1.02, 0.99, 1.01, 0.003, -0.002, 0.001],
            ),
        ];
        for volume_fix in [true, false] {
            let opts = UpdateOptions {
                volume_fix,
                ..UpdateOptions::default()
            };
            let f: Rows<Lanes<4>> = core::array::from_fn(|a| {
                core::array::from_fn(|b| Lanes(points.map(|p| p.0[a][b])))
            });
            let cp: [Lanes<4>; 6] = core::array::from_fn(|k| Lanes(points.map(|p| p.1[k])));
            let t = trial(&mat, &f, &cp);
            let mut a1 = [0.0; 4];
            let mut scale = [0.0; 4];
            let mut expected = [None; 4];
            for (l, (fl, cpl)) in points.iter().enumerate() {
                let tl = trial(&mat, fl, cpl);
                let check = check_trial(&mat, &opts, fl, &tl).unwrap();
                a1[l] = check.info.coefficients.a1;
                scale[l] = yield_surface::yield_scale(
                    &check.info.coefficients,
                    mat.params.yield_stress_pa,
                );
                if let Some(s) = check.plastic_scale {
                    let sol = corrector(&mat, &tl, a1[l], s).solve().unwrap();
                    let (up, cp_new) = plastic_return(&mat, &opts, fl, &tl, check.info, s).unwrap();
                    expected[l] = Some((sol, up, cp_new, tl.beta));
                }
            }
            let returned = expected.map(|e| e.is_some());
            assert_eq!(returned, [true, true, false, true]);
            assert_eq!(
                expected[1].unwrap().3,
                0.0,
                "the hydrostatic lane has βtr = 0"
            );
            let pick = |k: fn(&ReturnSolution) -> Real| {
                Lanes(expected.map(|e| e.map_or(0.0, |e| k(&e.0))))
            };
            let system = corrector(&mat, &t, Lanes(a1), Lanes(scale));
            let r = returned_state(
                &mat,
                &opts,
                &f,
                &t,
                &system,
                pick(|s| s.eps),
                pick(|s| s.delta),
                |l| returned[l],
            );
            for (l, e) in expected.iter().enumerate() {
                let Some((sol, up, cp_new, _)) = e else {
                    continue;
                };
                let lane = |v: &[Lanes<4>; 6]| v.map(|c| c.0[l].to_bits());
                assert_eq!(lane(&r.tau), up.tau.map(Real::to_bits), "τ of lane {l}");
                assert_eq!(
                    lane(&r.cp_inv),
                    cp_new.map(Real::to_bits),
                    "C_p⁻¹ of lane {l}"
                );
                let mut info = UpdateInfo::elastic(0.0, 0.0, up.info.coefficients, 0.0);
                info.eta = up.info.eta;
                info.record_return(sol, r.gamma.0[l], r.je.0[l]);
                assert_eq!(info, up.info, "diagnostics of lane {l}");
                let density = dissipation_density(&r.tau, Lanes([info.gamma; 4]), system.a1);
                assert_eq!(density.0[l].to_bits(), up.dissipation_density().to_bits());
            }
        }
    }

    /// The masked lane Newton gives every lane the scalar function's bits,
    /// whichever iteration it stops at: lanes far from and near to the
    /// root (different step counts), k = 0 (closed form), a lane not asked
    /// for (keeps s0) and a lane whose first step is not finite (f' = 0).
    #[test]
    fn volume_newton_in_lanes_has_the_scalar_bits() {
        // (k, det n, J^e, s0): s0 = sqrt(k^2/6) makes f'(s0) = 0.
        let cases: [(Real, Real, Real, Real); 8] = [
            (0.3, 0.05, 0.9, 1.2),
            (0.3, 0.05, 0.9, 0.93),
            (0.02, -0.1, 1.1, 1.0667),
            (0.0, 0.0, 0.8, 1.0),
            (0.5, 0.2, 1.0, 0.8),
            (0.6, 0.0, 1.0, libm::sqrt(0.06)),
            (0.1, 0.3, 0.95, 0.5),
            (0.2, -0.2, 1.05, 1.5),
        ];
        let solve = |l: usize| l != 4;
        let lane = |k: fn(&(Real, Real, Real, Real)) -> Real| Lanes(cases.map(|c| k(&c)));
        let s = spherical_part_for_volume_in(
            lane(|c| c.0),
            lane(|c| c.1),
            lane(|c| c.2),
            lane(|c| c.3),
            solve,
        );
        for (l, &(k, det_n, je, s0)) in cases.iter().enumerate() {
            let expected = if solve(l) {
                spherical_part_for_volume(k, det_n, je, s0)
            } else {
                s0
            };
            assert_eq!(s.0[l].to_bits(), expected.to_bits(), "lane {l}");
        }
        // Independently of the scalar function, which shares this code:
        // k = 0 is the closed form, and a first step that is not finite
        // (f'(s0) is exactly 0 in lane 5) leaves s0.
        assert_eq!(3.0 * cases[5].3 * cases[5].3, 0.5 * 0.6 * 0.6);
        assert_eq!(s.0[3].to_bits(), libm::cbrt(0.8 * 0.8).to_bits());
        assert_eq!(s.0[5].to_bits(), cases[5].3.to_bits());
        // The cases do take different numbers of steps (else the mask is
        // not exercised): the near start stops earlier than the far one.
        let (k, det_n, je) = (0.3, 0.05, 0.9);
        let (c1, c0) = (0.5 * k * k, k * k * k * det_n - je * je);
        let steps = |s0: Real| {
            let root = spherical_part_for_volume(k, det_n, je, s0);
            let mut s = s0;
            (1..=VOLUME_NEWTON_ITERATIONS)
                .find(|_| {
                    s -= (s * s * s - c1 * s + c0) / (3.0 * s * s - c1);
                    s.to_bits() == root.to_bits()
                })
                .unwrap_or(u32::MAX)
        };
        assert!(steps(0.93) < steps(1.2), "{} {}", steps(0.93), steps(1.2));
    }
}
