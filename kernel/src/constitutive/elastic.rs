//! Compressible neo-Hookean elasticity in the elastic left Cauchy–Green
//! tensor b^e (physics.md §1.1).
//!
//! ψ = ½μ(tr b^e − 3) + ½λ(J^e − 1)² − μ ln J^e, per unit reference volume;
//! τ = μ b^e + (1/3) h(J^e) 1 with h(J) = 3[λJ(J − 1) − μ].

use crate::lanes::Num;
use crate::material::Material;
use crate::tensor::{Voigt, scale_add_identity, trace};
use crate::{Real, math};

/// Volumetric stress function h(J) = 3[λJ(J − 1) − μ], Pa: the Kirchhoff
/// trace contributed by the volumetric part, so tr τ = μ tr b^e + h(J^e).
#[inline]
pub fn h(mat: &Material, je: Real) -> Real {
    h_lame(mat.lambda, mat.mu, je)
}

/// [`h`] from the Lamé constants λ, μ (Pa) directly.
#[inline]
pub fn h_lame<T: Num>(lambda: T, mu: T, je: T) -> T {
    T::splat(3.0) * (lambda * je * (je - T::splat(1.0)) - mu)
}

/// Derivative h'(J) = 3λ(2J − 1), Pa.
#[inline]
pub fn dh(mat: &Material, je: Real) -> Real {
    3.0 * mat.lambda * (2.0 * je - 1.0)
}

/// Kirchhoff stress τ = μ b^e + (1/3) h(J^e) 1, Pa, for an elastic left
/// Cauchy–Green tensor `be` (dimensionless, Voigt) with `je = √det b^e`.
#[inline]
pub fn kirchhoff<T: Num>(mat: &Material, be: &[T; 6], je: T) -> [T; 6] {
    // h/3 written out, so that b^e = 1 gives exactly τ = 0.
    let mu = T::splat(mat.mu);
    scale_add_identity(
        be,
        mu,
        T::splat(mat.lambda) * je * (je - T::splat(1.0)) - mu,
    )
}

/// Stored energy density ψ(b^e, J^e), J per m³ of reference volume.
#[inline]
pub fn energy_density(mat: &Material, be: &Voigt, je: Real) -> Real {
    0.5 * mat.mu * (trace(be) - 3.0) + 0.5 * mat.lambda * (je - 1.0) * (je - 1.0)
        - mat.mu * math::ln(je)
}

/// Stored energy density ψ of a point with deformation gradient `f` and
/// state `cp_inv` = C_p⁻¹: b^e = F C_p⁻¹ Fᵀ, J^e = det F √det C_p⁻¹; J/m³.
pub fn energy_density_of(mat: &Material, f: &crate::tensor::Mat3, cp_inv: &Voigt) -> Real {
    let be = crate::tensor::push_forward(f, cp_inv);
    let je = crate::tensor::det_mat(f) * math::sqrt(crate::tensor::det(cp_inv));
    energy_density(mat, &be, je)
}
