//! The plastic corrector: the scalar system in (ε, δ) of physics.md §1.4 and
//! its solvers.
//!
//! With ε = (4/3)γ a1 α and δ = (4/3)γ θ (γ the plastic multiplier), every
//! quantity of the returned state follows from ε and δ:
//!
//! ```text
//! θ(ε)  = θtr/(1+ε)                  Je(ε) = (1 − 1.5ε) Je_tr
//! α(ε)  = θ(ε) + h(Je(ε))            β     = βtr/(1 + ε + δ)
//! R1    = [a1 α(ε) δ − ε θ(ε)] / θtr                  (definition of δ, pole-free)
//! R2    = [β² + (a1/3) α² − (2/3) a2 σy²] / ((2/3) a2 σy²)   (consistency)
//! ```
//!
//! The default solver is a damped 2×2 Newton on (ε, δ); it needs no switch for
//! a1 → 0. a1 = 0 (von Mises) uses the closed-form radial return. If Newton
//! fails within [`MAX_NEWTON_ITERATIONS`], a bisection of the scalar residual
//! r(ε) on the bracket between 0 and the pole of δ(ε) takes over.

use crate::Real;
use crate::constitutive::elastic;
use crate::lanes::{Lanes, Num};
use crate::math;

/// Newton iterations before the bisection fallback takes over.
pub const MAX_NEWTON_ITERATIONS: u32 = 30;
/// Relative step size at which Newton has converged.
pub const NEWTON_STEP_TOL: Real = 1.0e-12;
/// Largest |R2| accepted from the fallback before the update is declared
/// non-converged.
pub const FALLBACK_RESIDUAL_MAX: Real = 1.0e-6;
/// Smallest admissible 1 + ε and 1 − 1.5ε during damped Newton steps.
const STEP_FLOOR: Real = 0.05;
/// Halvings of a Newton step before the damped step gives up on feasibility.
const MAX_HALVINGS: u32 = 60;
/// Bisection iterations (each halves the bracket; 200 exhaust f64).
const MAX_BISECTIONS: u32 = 200;

/// How the plastic corrector was solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReturnMethod {
    /// No return: the trial state was admissible.
    Elastic,
    /// Closed-form radial return (a1 = 0, von Mises).
    RadialReturn,
    /// Damped 2×2 Newton on (ε, δ).
    Newton,
    /// Bisection of r(ε) after Newton failed.
    Bisection,
}

/// The trial-state scalars and coefficients that define the corrector, for
/// one point (`T` = [`Real`]) or one point per lane (`T` = [`Lanes`]): the
/// residual, its Jacobian and the Newton step are written once over
/// [`Num`], so every lane gets the scalar bits.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReturnMapSystem<T = Real> {
    /// θtr = μ tr b^e,tr, Pa (> 0).
    pub theta_tr: T,
    /// Trial elastic volume ratio J^e,tr (> 0).
    pub je_tr: T,
    /// βtr = ‖dev τtr‖, Pa (≥ 0).
    pub beta_tr: T,
    /// Yield-surface coefficient a1 ≥ 0.
    pub a1: T,
    /// Yield scale (2/3) a2 σy², Pa² (> 0).
    pub yield_scale: T,
    /// Lamé λ, Pa.
    pub lambda: T,
    /// Shear modulus μ, Pa.
    pub mu: T,
}

/// A solution (or best iterate) of the corrector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReturnSolution {
    /// ε = (4/3)γ a1 α; has the sign of α.
    pub eps: Real,
    /// δ = (4/3)γ θ ≥ 0.
    pub delta: Real,
    /// Newton iterations, plus bisection steps if the fallback ran.
    pub iterations: u32,
    /// Which solver produced it.
    pub method: ReturnMethod,
    /// Final consistency residual R2 = φ/((2/3)a2σy²).
    pub residual: Real,
}

impl<T: Num> ReturnMapSystem<T> {
    /// θ(ε) = θtr/(1+ε), Pa.
    #[inline(always)]
    pub fn theta(&self, eps: T) -> T {
        self.theta_tr / (T::splat(1.0) + eps)
    }

    /// J^e(ε) = (1 − 1.5ε) J^e,tr (backward-Euler update of J^p).
    #[inline(always)]
    pub fn je(&self, eps: T) -> T {
        (T::splat(1.0) - T::splat(1.5) * eps) * self.je_tr
    }

    /// α(ε) = θ(ε) + h(J^e(ε)) = tr τ, Pa.
    #[inline(always)]
    pub fn alpha(&self, eps: T) -> T {
        self.theta(eps) + elastic::h_lame(self.lambda, self.mu, self.je(eps))
    }

    /// dα/dε, Pa.
    #[inline(always)]
    pub fn dalpha(&self, eps: T) -> T {
        -self.theta(eps) / (T::splat(1.0) + eps)
            - T::splat(4.5)
                * self.lambda
                * (T::splat(2.0) * self.je(eps) - T::splat(1.0))
                * self.je_tr
    }

    /// β = βtr/(1+ε+δ), Pa.
    #[inline(always)]
    pub fn beta(&self, eps: T, delta: T) -> T {
        self.beta_tr / (T::splat(1.0) + eps + delta)
    }

    /// Residuals [R1, R2] (both dimensionless; see the module docs).
    #[inline(always)]
    pub fn residual(&self, eps: T, delta: T) -> [T; 2] {
        let alpha = self.alpha(eps);
        let beta = self.beta(eps, delta);
        [
            (self.a1 * alpha * delta - eps * self.theta(eps)) / self.theta_tr,
            (beta * beta + (self.a1 / T::splat(3.0)) * alpha * alpha - self.yield_scale)
                / self.yield_scale,
        ]
    }

    /// Jacobian `[[∂R1/∂ε, ∂R1/∂δ], [∂R2/∂ε, ∂R2/∂δ]]` of [`Self::residual`].
    #[inline(always)]
    pub fn jacobian(&self, eps: T, delta: T) -> [[T; 2]; 2] {
        let alpha = self.alpha(eps);
        let dalpha = self.dalpha(eps);
        let beta = self.beta(eps, delta);
        let d_beta2 = -T::splat(2.0) * beta * beta / (T::splat(1.0) + eps + delta);
        [
            [
                (self.a1 * dalpha * delta - self.theta(eps) / (T::splat(1.0) + eps))
                    / self.theta_tr,
                self.a1 * alpha / self.theta_tr,
            ],
            [
                (d_beta2 + T::splat(2.0 / 3.0) * self.a1 * alpha * dalpha) / self.yield_scale,
                d_beta2 / self.yield_scale,
            ],
        ]
    }

    /// The full Newton step (Δε, Δδ) = −J⁻¹R at (ε, δ), before damping.
    #[inline(always)]
    pub fn newton_step(&self, eps: T, delta: T) -> (T, T) {
        let r = self.residual(eps, delta);
        let j = self.jacobian(eps, delta);
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let de = -(j[1][1] * r[0] - j[0][1] * r[1]) / det;
        let dd = -(j[0][0] * r[1] - j[1][0] * r[0]) / det;
        (de, dd)
    }
}

impl<const W: usize> ReturnMapSystem<Lanes<W>> {
    /// The systems of `W` points side by side.
    pub fn from_lanes(lanes: &[ReturnMapSystem; W]) -> Self {
        let pick = |f: fn(&ReturnMapSystem) -> Real| Lanes::from_fn(|l| f(&lanes[l]));
        Self {
            theta_tr: pick(|s| s.theta_tr),
            je_tr: pick(|s| s.je_tr),
            beta_tr: pick(|s| s.beta_tr),
            a1: pick(|s| s.a1),
            yield_scale: pick(|s| s.yield_scale),
            lambda: pick(|s| s.lambda),
            mu: pick(|s| s.mu),
        }
    }

    /// The damped Newton of [`ReturnMapSystem::solve`] in every lane with
    /// `active[l]`, side by side: the residuals, Jacobians and steps of all
    /// lanes at once, the damping and the convergence test lane by lane.
    /// Lane `l` of the result is the solution [`ReturnMapSystem::solve`]
    /// returns for lane `l`'s system, to the bit, when that Newton
    /// converges; `None` where it does not (or the lane is inactive), for
    /// the caller to solve that lane alone (bisection fallback, radial
    /// return). Inactive lanes must hold finite values (any lane's copy).
    pub fn newton(&self, active: [bool; W]) -> [Option<ReturnSolution>; W] {
        let mut out = [None; W];
        let mut eps = [0.0; W];
        let mut delta = [0.0; W];
        let mut live = active;
        for l in 0..W {
            if live[l] {
                delta[l] = self.lane(l).delta_start();
            }
        }
        for it in 1..=MAX_NEWTON_ITERATIONS {
            if !live.contains(&true) {
                break;
            }
            let (de, dd) = self.newton_step(Lanes(eps), Lanes(delta));
            for l in 0..W {
                if !live[l] {
                    continue;
                }
                match damped_update(eps[l], delta[l], de.0[l], dd.0[l]) {
                    NewtonUpdate::Failed => live[l] = false,
                    NewtonUpdate::Moved(e, d) => (eps[l], delta[l]) = (e, d),
                    NewtonUpdate::Converged(e, d) => {
                        live[l] = false;
                        out[l] = Some(self.lane(l).newton_solution(e, d, it));
                    }
                }
            }
        }
        out
    }

    /// The system of lane `l`.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> ReturnMapSystem {
        ReturnMapSystem {
            theta_tr: self.theta_tr.0[l],
            je_tr: self.je_tr.0[l],
            beta_tr: self.beta_tr.0[l],
            a1: self.a1.0[l],
            yield_scale: self.yield_scale.0[l],
            lambda: self.lambda.0[l],
            mu: self.mu.0[l],
        }
    }
}

/// What one damped Newton update did.
enum NewtonUpdate {
    /// The step was not finite: Newton failed at the current iterate.
    Failed,
    /// The new iterate (ε, δ), not yet converged.
    Moved(Real, Real),
    /// The new iterate (ε, δ), converged.
    Converged(Real, Real),
}

/// Applies the Newton step (`de`, `dd`) at (`eps`, `delta`), halved until
/// the iterate is feasible, and tests convergence.
#[inline(always)]
fn damped_update(eps: Real, delta: Real, de: Real, dd: Real) -> NewtonUpdate {
    if !(de.is_finite() && dd.is_finite()) {
        return NewtonUpdate::Failed;
    }
    let mut t = 1.0;
    let mut halvings = 0;
    while !ReturnMapSystem::feasible(eps + t * de, delta + t * dd) && halvings < MAX_HALVINGS {
        t *= 0.5;
        halvings += 1;
    }
    let eps = eps + t * de;
    let delta = math::max(delta + t * dd, 0.0);
    let converged = t == 1.0
        && math::abs(de) < NEWTON_STEP_TOL * (1.0 + math::abs(eps))
        && math::abs(dd) < NEWTON_STEP_TOL * (1.0 + delta);
    if converged {
        NewtonUpdate::Converged(eps, delta)
    } else {
        NewtonUpdate::Moved(eps, delta)
    }
}

impl ReturnMapSystem {
    /// Solves the corrector: radial return for a1 = 0, otherwise damped
    /// Newton with the bisection fallback. `Err` carries the best iterate
    /// when neither reaches |R2| ≤ [`FALLBACK_RESIDUAL_MAX`].
    pub fn solve(&self) -> Result<ReturnSolution, ReturnSolution> {
        if self.a1 == 0.0 {
            return Ok(self.radial_return());
        }
        let newton = self.newton();
        match newton {
            Ok(sol) => Ok(sol),
            Err(best) => {
                let mut sol = self.bisection().unwrap_or(best);
                sol.iterations += best.iterations;
                if math::abs(sol.residual) <= FALLBACK_RESIDUAL_MAX {
                    Ok(sol)
                } else {
                    Err(sol)
                }
            }
        }
    }

    /// Closed form for a1 = 0: ε = 0, β = √((2/3)a2)σy, δ = βtr/β − 1.
    pub fn radial_return(&self) -> ReturnSolution {
        let beta = math::sqrt(self.yield_scale);
        let delta = self.beta_tr / beta - 1.0;
        ReturnSolution {
            eps: 0.0,
            delta,
            iterations: 0,
            method: ReturnMethod::RadialReturn,
            residual: self.residual(0.0, delta)[1],
        }
    }

    /// Radial-return estimate of δ used as the Newton start.
    fn delta_start(&self) -> Real {
        let alpha = self.alpha(0.0);
        let room = math::max(
            self.yield_scale - (self.a1 / 3.0) * alpha * alpha,
            0.01 * self.yield_scale,
        );
        math::max(0.0, self.beta_tr / math::sqrt(room) - 1.0)
    }

    fn feasible(eps: Real, delta: Real) -> bool {
        1.0 + eps >= STEP_FLOOR && 1.0 - 1.5 * eps >= STEP_FLOOR && delta >= 0.0
    }

    /// A converged Newton iterate as a solution.
    fn newton_solution(&self, eps: Real, delta: Real, iterations: u32) -> ReturnSolution {
        ReturnSolution {
            eps,
            delta,
            iterations,
            method: ReturnMethod::Newton,
            residual: self.residual(eps, delta)[1],
        }
    }

    /// Damped Newton from (0, δ0); `Err` holds the last iterate.
    fn newton(&self) -> Result<ReturnSolution, ReturnSolution> {
        let (mut eps, mut delta) = (0.0, self.delta_start());
        for it in 1..=MAX_NEWTON_ITERATIONS {
            let (de, dd) = self.newton_step(eps, delta);
            match damped_update(eps, delta, de, dd) {
                NewtonUpdate::Failed => return Err(self.newton_solution(eps, delta, it)),
                NewtonUpdate::Moved(e, d) => (eps, delta) = (e, d),
                NewtonUpdate::Converged(e, d) => return Ok(self.newton_solution(e, d, it)),
            }
        }
        Err(self.newton_solution(eps, delta, MAX_NEWTON_ITERATIONS))
    }

    /// δ(ε) = εθ/(a1 α): the δ that satisfies R1 = 0 exactly.
    fn delta_of(&self, eps: Real) -> Real {
        eps * self.theta(eps) / (self.a1 * self.alpha(eps))
    }

    /// Scalar consistency residual r(ε)/((2/3)a2σy²) with δ = δ(ε).
    fn scalar_residual(&self, eps: Real) -> Real {
        self.residual(eps, self.delta_of(eps))[1]
    }

    /// Bisection of r(ε) between 0 and the pole ε_p of δ(ε) (the zero of α).
    /// `None` when no bracket is found.
    fn bisection(&self) -> Option<ReturnSolution> {
        let pole = self.pole()?;
        // r(0) = φtr > 0 and r → −1 (normalised) at the pole.
        let (mut lo, mut hi) = (0.0, pole);
        let mut iterations = 0;
        while iterations < MAX_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if self.scalar_residual(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            iterations += 1;
        }
        // Keep the bracket end nearer the surface.
        let eps = if math::abs(self.scalar_residual(lo)) <= math::abs(self.scalar_residual(hi)) {
            lo
        } else {
            hi
        };
        Some(ReturnSolution {
            eps,
            delta: self.delta_of(eps),
            iterations,
            method: ReturnMethod::Bisection,
            residual: self.scalar_residual(eps),
        })
    }

    /// ε_p, the zero of α(ε) on the side of the sign of αtr, by bisection
    /// inside the admissible domain −1 < ε < 2/3.
    fn pole(&self) -> Option<Real> {
        let alpha0 = self.alpha(0.0);
        let limit = if alpha0 > 0.0 { 2.0 / 3.0 } else { -1.0 };
        let (mut lo, mut hi) = (0.0, limit * (1.0 - 1.0e-12));
        let product = alpha0 * self.alpha(hi);
        if product.is_nan() || product >= 0.0 {
            return None;
        }
        for _ in 0..MAX_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if alpha0 * self.alpha(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        // The open bracket end on the trial side, so that α ≠ 0 there.
        Some(lo)
    }
}
