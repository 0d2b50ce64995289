//! The density-dependent elliptic yield surface (physics.md §1.1, §1.5).
//!
//! φ(τ, η) = ‖dev τ‖² + (a1/3)(tr τ)² − (2/3) a2 σ_y², with
//! a1 = c_p(1 − η²), a2 = (η² − η_c²)/(1 − η_c²) for η < 1 and a1 = 0,
//! a2 = 1 (von Mises) for η ≥ 1.

use crate::Real;
use crate::lanes::{Lanes, Num};
use crate::material::MaterialParams;

/// Smallest a2 the update accepts: below it (η ≤ η_c, extreme dilation) the
/// surface would be empty, so a2 is clamped here and the event flagged.
pub const A2_MIN: Real = 1.0e-6;

/// Yield-surface coefficients at one relative density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct YieldCoefficients {
    /// Pressure coefficient a1 ≥ 0.
    pub a1: Real,
    /// Size coefficient a2, in [`A2_MIN`], 1].
    pub a2: Real,
    /// True when a2 was clamped up to [`A2_MIN`] (η ≤ η_c).
    pub a2_clamped: bool,
}

/// The coefficients of the von Mises surface (η ≥ 1).
const VON_MISES: YieldCoefficients = YieldCoefficients {
    a1: 0.0,
    a2: 1.0,
    a2_clamped: false,
};

/// a1(η) and a2(η) for relative density `eta` (physics.md §1.1).
#[inline]
pub fn coefficients(params: &MaterialParams, eta: Real) -> YieldCoefficients {
    if eta >= 1.0 {
        return VON_MISES;
    }
    let (a1, a2) = porous_formula(params, eta);
    coefficients_from(eta, a1, a2)
}

/// a1 = c_p(1 − η²) and a2 = (η² − η_c²)/(1 − η_c²), the porous branch of
/// [`coefficients`] before a2 is clamped, over any [`Num`] (the lanes of an
/// element batch get the scalar bits).
#[inline(always)]
pub fn porous_formula<T: Num>(params: &MaterialParams, eta: T) -> (T, T) {
    let eta2 = eta * eta;
    let ec2 = params.eta_c * params.eta_c;
    let a2 = (eta2 - T::splat(ec2)) / T::splat(1.0 - ec2);
    (T::splat(params.cp) * (T::splat(1.0) - eta2), a2)
}

/// [`coefficients`] at `eta` from [`porous_formula`]'s `a1` and `a2`
/// there: von Mises for η ≥ 1, else a2 clamped up to [`A2_MIN`]. One lane
/// of [`coefficients_in_lanes`].
#[inline(always)]
pub fn coefficients_from(eta: Real, a1: Real, a2: Real) -> YieldCoefficients {
    coefficients_in_lanes(Lanes([eta]), Lanes([a1]), Lanes([a2])).lane(0)
}

/// [`YieldCoefficients`] of `W` lanes side by side (lane l = lane l of
/// each field).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoefficientLanes<const W: usize> {
    /// a1 of each lane.
    pub a1: Lanes<W>,
    /// a2 of each lane.
    pub a2: Lanes<W>,
    /// Whether each lane's a2 was clamped.
    pub a2_clamped: [bool; W],
}

impl<const W: usize> CoefficientLanes<W> {
    /// Lane `l`'s coefficients.
    ///
    /// # Panics
    /// If `l` ≥ `W`.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> YieldCoefficients {
        YieldCoefficients {
            a1: self.a1.0[l],
            a2: self.a2.0[l],
            a2_clamped: self.a2_clamped[l],
        }
    }
}

/// [`coefficients_from`] for `W` lanes at once. The tests pick without
/// branches (η ≥ 1 and the clamp are selections of each lane), so a batch
/// of elements gets them as vector compares and blends; lane by lane with
/// branches the element took 8 instructions more per element-step
/// (BENCHMARKS.md, session 36).
#[inline(always)]
pub fn coefficients_in_lanes<const W: usize>(
    eta: Lanes<W>,
    a1: Lanes<W>,
    a2: Lanes<W>,
) -> CoefficientLanes<W> {
    let mut c = CoefficientLanes {
        a1,
        a2,
        a2_clamped: [false; W],
    };
    for (l, clamped) in c.a2_clamped.iter_mut().enumerate() {
        let von_mises = eta.0[l] >= 1.0;
        let low = a2.0[l].is_nan() | (a2.0[l] < A2_MIN);
        *clamped = !von_mises & low;
        c.a1.0[l] = if von_mises { VON_MISES.a1 } else { a1.0[l] };
        c.a2.0[l] = if von_mises {
            VON_MISES.a2
        } else if low {
            A2_MIN
        } else {
            a2.0[l]
        };
    }
    c
}

/// Yield function φ from the deviatoric norm `beta` = ‖dev τ‖ and trace
/// `alpha` = tr τ of a Kirchhoff stress, Pa².
#[inline]
pub fn yield_function(c: &YieldCoefficients, yield_stress: Real, beta: Real, alpha: Real) -> Real {
    yield_function_of(c.a1, yield_scale(c, yield_stress), beta, alpha)
}

/// The scale (2/3) a2 σ_y² of the yield function, Pa²; tolerances on φ are
/// relative to it.
#[inline]
pub fn yield_scale(c: &YieldCoefficients, yield_stress: Real) -> Real {
    yield_scale_of(c.a2, yield_stress)
}

/// [`yield_scale`] over any [`Num`], from a2.
#[inline(always)]
pub fn yield_scale_of<T: Num>(a2: T, yield_stress: Real) -> T {
    T::splat(2.0 / 3.0) * a2 * T::splat(yield_stress) * T::splat(yield_stress)
}

/// [`yield_function`] over any [`Num`], from a1 and the scale
/// ([`yield_scale_of`]).
#[inline(always)]
pub fn yield_function_of<T: Num>(a1: T, scale: T, beta: T, alpha: T) -> T {
    beta * beta + (a1 / T::splat(3.0)) * alpha * alpha - scale
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::GranuleType;

    /// The pieces an element batch evaluates in lanes give each lane the
    /// bits of the scalar [`coefficients`], [`yield_scale`] and
    /// [`yield_function`]: lanes past η = 1 (von Mises), just below it,
    /// porous, at and below η_c (a2 clamped), and NaN, side by side.
    #[test]
    fn lanes_give_the_scalar_coefficients_scale_and_yield_function() {
        let params = GranuleType::B1.params();
        let etas = [
            1.3,
            1.0,
            1.0 - 1e-12,
            0.999,
            0.8,
            0.6,
            params.eta_c,
            0.1,
            Real::NAN,
            0.35,
            2.0,
            0.2001,
        ];
        let (beta, alpha) = (7.0e3, -2.0e4);
        let mut seen = (false, false, false);
        for chunk in etas.chunks_exact(4) {
            let eta = Lanes::<4>(core::array::from_fn(|l| chunk[l]));
            let (a1_formula, a2_formula) = porous_formula(&params, eta);
            let lanes = coefficients_in_lanes(eta, a1_formula, a2_formula);
            let c: [YieldCoefficients; 4] = core::array::from_fn(|l| lanes.lane(l));
            let scale = yield_scale_of(lanes.a2, params.yield_stress_pa);
            let phi = yield_function_of(
                lanes.a1,
                scale,
                Lanes::<4>::splat(beta),
                Lanes::<4>::splat(alpha),
            );
            for l in 0..4 {
                let want = coefficients(&params, eta.0[l]);
                let bits = |c: &YieldCoefficients| (c.a1.to_bits(), c.a2.to_bits(), c.a2_clamped);
                assert_eq!(bits(&c[l]), bits(&want), "η {}", eta.0[l]);
                let s = yield_scale(&want, params.yield_stress_pa);
                assert_eq!(scale.0[l].to_bits(), s.to_bits(), "η {}", eta.0[l]);
                let f = yield_function(&want, params.yield_stress_pa, beta, alpha);
                assert_eq!(phi.0[l].to_bits(), f.to_bits(), "η {}", eta.0[l]);
                seen.0 |= eta.0[l] >= 1.0;
                seen.1 |= want.a2_clamped;
                seen.2 |= want.a1 > 0.0 && !want.a2_clamped;
            }
        }
        assert_eq!(
            seen,
            (true, true, true),
            "von Mises, clamped and porous lanes"
        );
    }

    /// The rule of physics.md §1.1 lane by lane, against values worked out
    /// here rather than by the code under test (the scalar
    /// [`coefficients_from`] is [`coefficients_in_lanes`] with one lane):
    /// a1 = c_p(1 − η²) and a2 = (η² − η_c²)/(1 − η_c²) below η = 1,
    /// a2 raised to [`A2_MIN`] and flagged where it falls below it or is
    /// NaN, von Mises (0, 1, not flagged) from η = 1 on.
    #[test]
    fn each_lane_follows_the_porous_rule_the_clamp_and_von_mises() {
        let params = GranuleType::B1.params();
        let (cp, ec2) = (params.cp, params.eta_c * params.eta_c);
        assert!(ec2 > 0.0 && ec2 < 1.0);
        let porous = |eta: Real| (cp * (1.0 - eta * eta), (eta * eta - ec2) / (1.0 - ec2));
        // Porous, at η_c (a2 = 0 < A2_MIN), von Mises (where the porous
        // formula would give a1 < 0, a2 > 1), NaN.
        let eta = Lanes([0.7, params.eta_c, 1.3, Real::NAN]);
        let (a1_formula, a2_formula) = porous_formula(&params, eta);
        let c = coefficients_in_lanes(eta, a1_formula, a2_formula);
        let triple = |y: YieldCoefficients| (y.a1, y.a2, y.a2_clamped);
        let (a1_want, a2_want) = porous(0.7);
        assert!(a2_want > A2_MIN);
        assert_eq!(triple(c.lane(0)), (a1_want, a2_want, false));
        assert_eq!(triple(c.lane(1)), (porous(params.eta_c).0, A2_MIN, true));
        assert_eq!(triple(c.lane(2)), (0.0, 1.0, false));
        assert!(c.lane(3).a1.is_nan());
        assert_eq!((c.lane(3).a2, c.lane(3).a2_clamped), (A2_MIN, true));
        // A lane's result does not depend on its neighbours.
        for l in 0..4 {
            let one = coefficients_from(eta.0[l], a1_formula.0[l], a2_formula.0[l]);
            let lane = c.lane(l);
            assert_eq!(one.a2.to_bits(), lane.a2.to_bits(), "lane {l}");
            assert_eq!(one.a2_clamped, lane.a2_clamped, "lane {l}");
        }
    }
}
