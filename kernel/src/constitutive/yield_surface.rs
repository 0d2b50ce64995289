//! The density-dependent elliptic yield surface (physics.md §1.1, §1.5).
//!
//! φ(τ, η) = ‖dev τ‖² + (a1/3)(tr τ)² − (2/3) a2 σ_y², with
//! a1 = c_p(1 − η²), a2 = (η² − η_c²)/(1 − η_c²) for η < 1 and a1 = 0,
//! a2 = 1 (von Mises) for η ≥ 1.

use crate::Real;
use crate::lanes::Num;
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
/// there: von Mises for η ≥ 1, else a2 clamped up to [`A2_MIN`].
#[inline(always)]
pub fn coefficients_from(eta: Real, a1: Real, a2: Real) -> YieldCoefficients {
    if eta >= 1.0 {
        return VON_MISES;
    }
    let a2_clamped = a2.is_nan() || a2 < A2_MIN;
    YieldCoefficients {
        a1,
        a2: if a2_clamped { A2_MIN } else { a2 },
        a2_clamped,
    }
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
