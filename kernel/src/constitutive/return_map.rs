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
use crate::lanes::{Lanes, Num, lane_bit};
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

/// The trial-state scalars and coefficients that define the corrector.
///
/// Over any [`Num`] for the returned state's formulas ([`Self::theta`],
/// [`Self::je`], [`Self::alpha`], [`Self::beta`]): an element batch
/// evaluates them for all its lanes at once with the scalar bits
/// (`update::returned_state`), and the Newton solve likewise: the scalar
/// [`ReturnMapSystem::solve`] is its one-lane case, and
/// [`ReturnMapSystem::solve_lanes`] runs it for a batch's lanes at once.
/// The radial return and the bisection fallback are scalar (`T = Real`).
#[derive(Clone, Copy, Debug, PartialEq)]
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

    /// β = βtr/(1+ε+δ), Pa.
    #[inline(always)]
    pub fn beta(&self, eps: T, delta: T) -> T {
        self.beta_tr / (T::splat(1.0) + eps + delta)
    }

    /// The consistency residual R2 = [β² + (a1/3)α² − (2/3)a2σy²] /
    /// ((2/3)a2σy²) (dimensionless).
    #[inline(always)]
    pub fn consistency(&self, eps: T, delta: T) -> T {
        let alpha = self.alpha(eps);
        let beta = self.beta(eps, delta);
        (beta * beta + (self.a1 / T::splat(3.0)) * alpha * alpha - self.yield_scale)
            / self.yield_scale
    }

    /// The residual and Jacobian that Newton iterates on: R1 multiplied by
    /// θtr (Pa) and R2 by (2/3)a2σy² (Pa²), i.e. without the normalising
    /// divisions. A Newton step is the same for any scaling of the rows, and
    /// the step is Newton's convergence test, so only round-off changes; the
    /// normalised [`ReturnMapSystem::residual`] stays what is reported.
    ///
    /// Three divisions per call, two of them in sequence (1/(1+ε), then
    /// 1/det J in [`Self::newton_in`]): the corrector is bound by their
    /// latency (BENCHMARKS.md, session 23), where the normalised pair took
    /// about ten.
    #[inline(always)]
    fn linearise(&self, eps: T, delta: T) -> ([T; 2], [[T; 2]; 2]) {
        let one = T::splat(1.0);
        let inv_e = one / (one + eps);
        let inv_ed = one / (one + eps + delta);
        let theta = self.theta_tr * inv_e;
        let je = self.je(eps);
        let alpha = theta + elastic::h_lame(self.lambda, self.mu, je);
        // dθ/dε = −θ/(1+ε); d(εθ)/dε = θ/(1+ε); dα/dε = dθ/dε + h'(J^e) dJ^e/dε
        // with dJ^e/dε = −1.5 J^e,tr.
        let theta_e = theta * inv_e;
        let dalpha =
            -theta_e - T::splat(4.5) * self.lambda * (T::splat(2.0) * je - one) * self.je_tr;
        let beta = self.beta_tr * inv_ed;
        let beta2 = beta * beta;
        let d_beta2 = -T::splat(2.0) * beta2 * inv_ed;
        let a1_alpha = self.a1 * alpha;
        (
            [
                a1_alpha * delta - eps * theta,
                beta2 + (self.a1 / T::splat(3.0)) * alpha * alpha - self.yield_scale,
            ],
            [
                [self.a1 * dalpha * delta - theta_e, a1_alpha],
                [d_beta2 + T::splat(2.0 / 3.0) * a1_alpha * dalpha, d_beta2],
            ],
        )
    }

    /// Radial-return estimate of δ used as the Newton start.
    #[inline(always)]
    fn delta_start(&self) -> T {
        let alpha = self.alpha(T::splat(0.0));
        let free = self.yield_scale - (self.a1 / T::splat(3.0)) * alpha * alpha;
        let floor = T::splat(0.01) * self.yield_scale;
        let room = T::from_fn(|l| math::max(free.lane(l), floor.lane(l)));
        let start = self.beta_tr / room.sqrt() - T::splat(1.0);
        T::from_fn(|l| math::max(0.0, start.lane(l)))
    }

    /// Damped Newton from (0, δ0) in every lane whose bit is set in
    /// `lanes`, side by side: each lane steps, damps and stops exactly as
    /// the one-lane (scalar) instance would for its system, so it gets the
    /// scalar bits. Returns the last iterates (ε, δ) and the bits of the
    /// lanes that converged; `iterations[l]` is lane l's count (where it
    /// stopped: converged, a step not finite, or [`MAX_NEWTON_ITERATIONS`]).
    /// A lane not in `lanes` is computed along and left at (0, δ0).
    #[inline(always)]
    fn newton_in(&self, lanes: u64, iterations: &mut [u32]) -> (T, T, u64) {
        // One bit per lane: checked when the function is instantiated.
        const { assert!(T::LANES <= 64, "at most 64 lanes") };
        let (mut eps, mut delta) = (T::splat(0.0), self.delta_start());
        let (mut iterating, mut converged) = (lanes, 0);
        for it in 1..=MAX_NEWTON_ITERATIONS {
            if iterating == 0 {
                return (eps, delta, converged);
            }
            let (r, j) = self.linearise(eps, delta);
            let inv_det = T::splat(1.0) / (j[0][0] * j[1][1] - j[0][1] * j[1][0]);
            let de = -(j[1][1] * r[0] - j[0][1] * r[1]) * inv_det;
            let dd = -(j[0][0] * r[1] - j[1][0] * r[0]) * inv_det;
            // With several lanes, the full step where every iterating lane
            // can take it (finite and feasible: t = 1, as `damping` finds
            // first); else (and for one lane) per lane a step that is not
            // finite stops the lane (keeping its iterate), and `damping`
            // finds t.
            let mut full = 0;
            if T::LANES > 1 {
                for l in 0..T::LANES {
                    let (de, dd) = (de.lane(l), dd.lane(l));
                    let ok = de.is_finite()
                        & dd.is_finite()
                        & feasible(eps.lane(l) + de, delta.lane(l) + dd);
                    full |= u64::from(ok) << l;
                }
            }
            let mut stepping = iterating;
            let t = if T::LANES > 1 && iterating & !full == 0 {
                T::splat(1.0)
            } else {
                T::from_fn(|l| {
                    if !lane_bit(iterating, l) {
                        return 0.0;
                    }
                    let (de, dd) = (de.lane(l), dd.lane(l));
                    if !(de.is_finite() && dd.is_finite()) {
                        stepping &= !(1 << l);
                        iterations[l] = it;
                        return 0.0;
                    }
                    damping(eps.lane(l), delta.lane(l), de, dd)
                })
            };
            let (stepped_eps, stepped_delta) = (eps + t * de, delta + t * dd);
            eps = T::from_fn(|l| {
                if lane_bit(stepping, l) {
                    stepped_eps.lane(l)
                } else {
                    eps.lane(l)
                }
            });
            delta = T::from_fn(|l| {
                if lane_bit(stepping, l) {
                    math::max(stepped_delta.lane(l), 0.0)
                } else {
                    delta.lane(l)
                }
            });
            iterating = stepping;
            for (l, count) in iterations.iter_mut().enumerate().take(T::LANES) {
                if lane_bit(stepping, l)
                    & (t.lane(l) == 1.0)
                    & (math::abs(de.lane(l)) < NEWTON_STEP_TOL * (1.0 + math::abs(eps.lane(l))))
                    & (math::abs(dd.lane(l)) < NEWTON_STEP_TOL * (1.0 + delta.lane(l)))
                {
                    iterating &= !(1 << l);
                    converged |= 1 << l;
                    *count = it;
                }
            }
        }
        for (l, count) in iterations.iter_mut().enumerate().take(T::LANES) {
            if lane_bit(iterating, l) {
                *count = MAX_NEWTON_ITERATIONS;
            }
        }
        (eps, delta, converged)
    }
}

/// Whether (ε, δ) lies in the set Newton's steps are kept in: 1 + ε ≥
/// 0.05, 1 − 1.5ε ≥ 0.05 and δ ≥ 0.
///
/// The tests here, and the lane Newton's full-step and convergence checks,
/// are joined with `&`, not `&&`: without a branch per test they take fewer
/// instructions in the batch (BENCHMARKS.md, session 35).
#[inline(always)]
fn feasible(eps: Real, delta: Real) -> bool {
    (1.0 + eps >= STEP_FLOOR) & (1.0 - 1.5 * eps >= STEP_FLOOR) & (delta >= 0.0)
}

/// The damping factor of a Newton step (Δε, Δδ) from (ε, δ): 1, halved
/// until the step lands in the [`feasible`] set or [`MAX_HALVINGS`] times.
#[inline(always)]
fn damping(eps: Real, delta: Real, de: Real, dd: Real) -> Real {
    let mut t = 1.0;
    let mut halvings = 0;
    while !feasible(eps + t * de, delta + t * dd) && halvings < MAX_HALVINGS {
        t *= 0.5;
        halvings += 1;
    }
    t
}

impl<const W: usize> ReturnMapSystem<Lanes<W>> {
    /// The system of lane `l`.
    ///
    /// # Panics
    /// If `l` ≥ `W` (an index into the lanes, as `Num::lane`'s).
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

    /// [`ReturnMapSystem::solve`] of every lane whose bit is set in `lanes`,
    /// into `solutions[l]` (the others are left as they are), with the
    /// scalar bits: the Newton iterations of the lanes with a1 ≠ 0 run side
    /// by side (`newton_in`), so the batch waits on one chain of
    /// divisions instead of one per lane; the radial return and the
    /// bisection fallback stay per lane. `false` as soon as a lane's solve
    /// fails (`solve` gives `Err`). Bits of `lanes` at or above `W` are
    /// ignored. Not inlined, like the batch's
    /// `return_lanes`, so that the elastic path keeps its registers.
    #[inline(never)]
    pub fn solve_lanes(&self, lanes: u64, solutions: &mut [Option<ReturnSolution>; W]) -> bool {
        if lanes.is_power_of_two() {
            // One lane: its scalar solve, without the other lanes in tow.
            let l = lanes.trailing_zeros() as usize;
            let Some(solution) = solutions.get_mut(l) else {
                return true;
            };
            return match self.lane(l).solve() {
                Ok(sol) => {
                    *solution = Some(sol);
                    true
                }
                Err(_) => false,
            };
        }
        let mut newton = 0;
        for l in 0..W {
            newton |= u64::from(lane_bit(lanes, l) && self.a1.0[l] != 0.0) << l;
        }
        let mut iterations = [0; W];
        let (eps, delta, converged) = self.newton_in(newton, &mut iterations);
        let residual = self.consistency(eps, delta);
        for (l, solution) in solutions.iter_mut().enumerate() {
            if !lane_bit(lanes, l) {
                continue;
            }
            let solved = if !lane_bit(newton, l) {
                Ok(self.lane(l).radial_return())
            } else {
                let sol = ReturnSolution {
                    eps: eps.0[l],
                    delta: delta.0[l],
                    iterations: iterations[l],
                    method: ReturnMethod::Newton,
                    residual: residual.0[l],
                };
                if lane_bit(converged, l) {
                    Ok(sol)
                } else {
                    self.lane(l).fallback(sol)
                }
            };
            match solved {
                Ok(sol) => *solution = Some(sol),
                Err(_) => return false,
            }
        }
        true
    }
}

impl ReturnMapSystem {
    /// Residuals [R1, R2] (both dimensionless; see the module docs).
    pub fn residual(&self, eps: Real, delta: Real) -> [Real; 2] {
        [
            (self.a1 * self.alpha(eps) * delta - eps * self.theta(eps)) / self.theta_tr,
            self.consistency(eps, delta),
        ]
    }

    /// Jacobian `[[∂R1/∂ε, ∂R1/∂δ], [∂R2/∂ε, ∂R2/∂δ]]` of [`Self::residual`]:
    /// the rows of the Jacobian Newton iterates on (without the normalising
    /// divisions, see `linearise`) divided by θtr and by (2/3)a2σy².
    pub fn jacobian(&self, eps: Real, delta: Real) -> [[Real; 2]; 2] {
        let (_, j) = self.linearise(eps, delta);
        let row = [1.0 / self.theta_tr, 1.0 / self.yield_scale];
        core::array::from_fn(|i| [j[i][0] * row[i], j[i][1] * row[i]])
    }

    /// Solves the corrector: radial return for a1 = 0, otherwise damped
    /// Newton with the bisection fallback. `Err` carries the best iterate
    /// when neither reaches |R2| ≤ [`FALLBACK_RESIDUAL_MAX`].
    pub fn solve(&self) -> Result<ReturnSolution, ReturnSolution> {
        if self.a1 == 0.0 {
            return Ok(self.radial_return());
        }
        self.newton().or_else(|best| self.fallback(best))
    }

    /// The result of `solve` after Newton failed with `best`: the
    /// bisection's solution (or `best`) if its |R2| is at most
    /// [`FALLBACK_RESIDUAL_MAX`]. Out of line: Newton nearly always
    /// converges.
    #[cold]
    fn fallback(&self, best: ReturnSolution) -> Result<ReturnSolution, ReturnSolution> {
        let mut sol = self.bisection().unwrap_or(best);
        sol.iterations += best.iterations;
        if math::abs(sol.residual) <= FALLBACK_RESIDUAL_MAX {
            Ok(sol)
        } else {
            Err(sol)
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

    /// Damped Newton from (0, δ0): the one-lane [`Self::newton_in`]. `Err`
    /// holds the last iterate.
    fn newton(&self) -> Result<ReturnSolution, ReturnSolution> {
        let mut iterations = [0];
        let (eps, delta, converged) = self.newton_in(1, &mut iterations);
        let sol = ReturnSolution {
            eps,
            delta,
            iterations: iterations[0],
            method: ReturnMethod::Newton,
            residual: self.residual(eps, delta)[1],
        };
        if converged == 1 { Ok(sol) } else { Err(sol) }
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
