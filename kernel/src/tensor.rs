//! Second-order tensors in 3-D: full matrices and symmetric tensors in Voigt
//! storage.
//!
//! * [`Mat3`] is a general 3×3 tensor (deformation gradient `F`, rotations),
//!   `m[(i, j)]` is the component in row `i`, column `j`.
//! * [`Voigt`] stores a symmetric tensor as six numbers in the order
//!   `[xx, yy, zz, yz, xz, xy]` (indices [`XX`] … [`XY`]); shear components are
//!   stored once, without a factor 2.

use crate::lanes::Num;
use crate::{Real, math};

/// General 3×3 tensor.
pub type Mat3 = nalgebra::Matrix3<Real>;

/// Symmetric tensor in Voigt order `[xx, yy, zz, yz, xz, xy]`.
pub type Voigt = [Real; 6];

/// Voigt index of the xx component.
pub const XX: usize = 0;
/// Voigt index of the yy component.
pub const YY: usize = 1;
/// Voigt index of the zz component.
pub const ZZ: usize = 2;
/// Voigt index of the yz component.
pub const YZ: usize = 3;
/// Voigt index of the xz component.
pub const XZ: usize = 4;
/// Voigt index of the xy component.
pub const XY: usize = 5;

/// The identity in Voigt storage.
pub const VOIGT_IDENTITY: Voigt = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0];

/// Full symmetric matrix from Voigt storage.
#[inline]
pub fn mat_from_voigt(v: &Voigt) -> Mat3 {
    Mat3::new(
        v[XX], v[XY], v[XZ], //
        v[XY], v[YY], v[YZ], //
        v[XZ], v[YZ], v[ZZ],
    )
}

/// Voigt storage of the symmetric part of `m`, `(m + mᵀ)/2`.
#[inline]
pub fn voigt_from_mat(m: &Mat3) -> Voigt {
    [
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        0.5 * (m[(1, 2)] + m[(2, 1)]),
        0.5 * (m[(0, 2)] + m[(2, 0)]),
        0.5 * (m[(0, 1)] + m[(1, 0)]),
    ]
}

/// A general 3×3 tensor as rows, `m[i][j]` = row `i`, column `j`, over any
/// [`Num`]: the form the element batches use ([`crate::lanes`]); the
/// [`Mat3`] functions below are its `T = Real` instances.
pub type Rows<T> = [[T; 3]; 3];

/// The rows of a [`Mat3`].
#[inline(always)]
pub fn rows(m: &Mat3) -> Rows<Real> {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// The [`Mat3`] of rows `m`.
#[inline(always)]
pub fn from_rows(m: &Rows<Real>) -> Mat3 {
    Mat3::new(
        m[0][0], m[0][1], m[0][2], //
        m[1][0], m[1][1], m[1][2], //
        m[2][0], m[2][1], m[2][2],
    )
}

/// Full symmetric matrix (as rows) from Voigt storage.
#[inline(always)]
pub fn rows_from_voigt<T: Num>(v: &[T; 6]) -> Rows<T> {
    [
        [v[XX], v[XY], v[XZ]],
        [v[XY], v[YY], v[YZ]],
        [v[XZ], v[YZ], v[ZZ]],
    ]
}

/// Voigt storage of the symmetric part of `m`, `(m + mᵀ)/2` (as
/// [`voigt_from_mat`]).
#[inline(always)]
pub fn voigt_from_rows<T: Num>(m: &Rows<T>) -> [T; 6] {
    let half = T::splat(0.5);
    [
        m[0][0],
        m[1][1],
        m[2][2],
        half * (m[1][2] + m[2][1]),
        half * (m[0][2] + m[2][0]),
        half * (m[0][1] + m[1][0]),
    ]
}

/// Trace of a symmetric tensor.
#[inline]
pub fn trace<T: Num>(v: &[T; 6]) -> T {
    v[XX] + v[YY] + v[ZZ]
}

/// Deviator `v − (tr v / 3) 1`.
#[inline]
pub fn deviator<T: Num>(v: &[T; 6]) -> [T; 6] {
    let m = trace(v) / T::splat(3.0);
    [v[XX] - m, v[YY] - m, v[ZZ] - m, v[YZ], v[XZ], v[XY]]
}

/// Double contraction `a : b` of two symmetric tensors.
#[inline]
pub fn ddot<T: Num>(a: &[T; 6], b: &[T; 6]) -> T {
    a[XX] * b[XX]
        + a[YY] * b[YY]
        + a[ZZ] * b[ZZ]
        + T::splat(2.0) * (a[YZ] * b[YZ] + a[XZ] * b[XZ] + a[XY] * b[XY])
}

/// Frobenius norm `√(v : v)` of a symmetric tensor.
#[inline]
pub fn norm<T: Num>(v: &[T; 6]) -> T {
    ddot(v, v).sqrt()
}

/// Determinant of a symmetric tensor.
#[inline]
pub fn det<T: Num>(v: &[T; 6]) -> T {
    v[XX] * (v[YY] * v[ZZ] - v[YZ] * v[YZ]) - v[XY] * (v[XY] * v[ZZ] - v[YZ] * v[XZ])
        + v[XZ] * (v[XY] * v[YZ] - v[YY] * v[XZ])
}

/// `a·v + b·1` for a symmetric `v`.
#[inline]
pub fn scale_add_identity<T: Num>(v: &[T; 6], a: T, b: T) -> [T; 6] {
    [
        a * v[XX] + b,
        a * v[YY] + b,
        a * v[ZZ] + b,
        a * v[YZ],
        a * v[XZ],
        a * v[XY],
    ]
}

/// Push-forward `F S Fᵀ` of a symmetric `S`, returned symmetric.
///
/// The two products are written out (each entry summed k = 0, 1, 2 as
/// nalgebra does, so the same bits): whether nalgebra's generic `Mul` was
/// inlined here depended on rustc's partitioning of the crate, and out of
/// line it cost 6 % of a bed run.
#[inline]
pub fn push_forward(f: &Mat3, s: &Voigt) -> Voigt {
    push_forward_rows(&rows(f), s)
}

/// [`push_forward`] over rows: every entry of `F S` and of `(F S) Fᵀ` summed
/// k = 0, 1, 2, then symmetrised.
#[inline(always)]
pub fn push_forward_rows<T: Num>(f: &Rows<T>, s: &[T; 6]) -> [T; 6] {
    let s = rows_from_voigt(s);
    // Loops rather than `array::from_fn`, which rustc left out of line.
    let mut fs = [[T::splat(0.0); 3]; 3];
    for (fs_i, f_i) in fs.iter_mut().zip(f) {
        for (j, fs_ij) in fs_i.iter_mut().enumerate() {
            *fs_ij = f_i[0] * s[0][j] + f_i[1] * s[1][j] + f_i[2] * s[2][j];
        }
    }
    let mut fsft = [[T::splat(0.0); 3]; 3];
    for (fsft_i, fs_i) in fsft.iter_mut().zip(&fs) {
        for (fsft_ij, f_j) in fsft_i.iter_mut().zip(f) {
            *fsft_ij = fs_i[0] * f_j[0] + fs_i[1] * f_j[1] + fs_i[2] * f_j[2];
        }
    }
    voigt_from_rows(&fsft)
}

/// Inverse of `m` given its (non-zero) determinant, by cofactors.
///
/// The caller has checked `det ≠ 0`; no pivoting or rank test is done.
#[inline]
pub fn inverse_with_det(m: &Mat3, det: Real) -> Mat3 {
    from_rows(&inverse_rows_with_det(&rows(m), det))
}

/// [`inverse_with_det`] over rows.
#[inline(always)]
pub fn inverse_rows_with_det<T: Num>(m: &Rows<T>, det: T) -> Rows<T> {
    let c = |i: usize, j: usize| m[i][j];
    let inv_det = T::splat(1.0) / det;
    [
        [
            (c(1, 1) * c(2, 2) - c(1, 2) * c(2, 1)) * inv_det,
            (c(0, 2) * c(2, 1) - c(0, 1) * c(2, 2)) * inv_det,
            (c(0, 1) * c(1, 2) - c(0, 2) * c(1, 1)) * inv_det,
        ],
        [
            (c(1, 2) * c(2, 0) - c(1, 0) * c(2, 2)) * inv_det,
            (c(0, 0) * c(2, 2) - c(0, 2) * c(2, 0)) * inv_det,
            (c(0, 2) * c(1, 0) - c(0, 0) * c(1, 2)) * inv_det,
        ],
        [
            (c(1, 0) * c(2, 1) - c(1, 1) * c(2, 0)) * inv_det,
            (c(0, 1) * c(2, 0) - c(0, 0) * c(2, 1)) * inv_det,
            (c(0, 0) * c(1, 1) - c(0, 1) * c(1, 0)) * inv_det,
        ],
    ]
}

/// Determinant of a general 3×3 tensor (cofactor expansion along row 0).
#[inline]
pub fn det_mat(m: &Mat3) -> Real {
    det_rows(&rows(m))
}

/// [`det_mat`] over rows.
#[inline(always)]
pub fn det_rows<T: Num>(m: &Rows<T>) -> T {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Kirchhoff pressure `p = −tr τ / 3` (positive in compression), Pa.
#[inline]
pub fn pressure(tau: &Voigt) -> Real {
    -trace(tau) / 3.0
}

/// Von Mises equivalent stress `√(3/2) ‖dev s‖` of a symmetric stress, Pa.
#[inline]
pub fn von_mises(s: &Voigt) -> Real {
    math::sqrt(1.5) * norm(&deviator(s))
}

/// Cauchy stress `σ = τ / J` from Kirchhoff stress `τ` and `J = det F`.
#[inline]
pub fn cauchy_from_kirchhoff(tau: &Voigt, j: Real) -> Voigt {
    scale_add_identity(tau, 1.0 / j, 0.0)
}

/// The smallest eigenvalue of the symmetric 3×3 matrix `j` (closed form,
/// no iteration; NaN in, NaN out). Near a repeated root the closed form's
/// acos works near ±1 and the result carries ~1e-8 relative error.
pub fn smallest_eigenvalue(j: &Mat3) -> Real {
    let q = (j[(0, 0)] + j[(1, 1)] + j[(2, 2)]) / 3.0;
    let off = j[(0, 1)] * j[(0, 1)] + j[(0, 2)] * j[(0, 2)] + j[(1, 2)] * j[(1, 2)];
    let diag = [0, 1, 2].map(|a| j[(a, a)] - q);
    let p2 = diag[0] * diag[0] + diag[1] * diag[1] + diag[2] * diag[2] + 2.0 * off;
    if p2 == 0.0 {
        return q;
    }
    let p = math::sqrt(p2 / 6.0);
    let mut b = *j;
    for a in 0..3 {
        b[(a, a)] -= q;
    }
    let half_det = det_mat(&(b / p)) / 2.0;
    let phi = math::acos(half_det.clamp(-1.0, 1.0)) / 3.0;
    q + 2.0 * p * math::cos(phi + 2.0 * core::f64::consts::FRAC_PI_3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voigt_round_trip_and_det_match_nalgebra() {
        let v = [1.3, 0.7, 2.1, 0.11, -0.23, 0.31];
        let m = mat_from_voigt(&v);
        assert_eq!(voigt_from_mat(&m), v);
        assert!((det(&v) - m.determinant()).abs() < 1e-14);
        assert!((det_mat(&m) - m.determinant()).abs() < 1e-14);
        let inv = inverse_with_det(&m, det_mat(&m));
        assert!((inv * m - Mat3::identity()).norm() < 1e-14);
        assert!((norm(&v) - m.norm()).abs() < 1e-14);
    }

    #[test]
    fn the_smallest_eigenvalue_of_rotated_diagonals() {
        // R = rotation by 0.7 rad about (1, 2, 2)/3.
        let axis = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
        let (c, s) = (math::cos(0.7), math::sin(0.7));
        let r = Mat3::from_fn(|a, b| {
            let k = [
                [0.0, -axis[2], axis[1]],
                [axis[2], 0.0, -axis[0]],
                [-axis[1], axis[0], 0.0],
            ];
            (if a == b { c } else { 0.0 }) + (1.0 - c) * axis[a] * axis[b] + s * k[a][b]
        });
        for (d, smallest) in [
            ([1.0, 2.0, 5.0], 1.0),
            ([5.0, 2.0, 1.0], 1.0),
            ([3.0, 3.0, 7.0], 3.0),
            ([7.0, 3.0, 3.0], 3.0),
            ([4.0, 4.0, 4.0], 4.0),
            ([2.0, 9.0, 5.0], 2.0),
            ([1e-3, 1.0, 1.0], 1e-3),
        ] {
            let j = r * Mat3::from_diagonal(&nalgebra::Vector3::from(d)) * r.transpose();
            let got = smallest_eigenvalue(&j);
            // At a repeated root acos works near ±1, where it loses half the
            // digits: ~1e-8 relative (hence the callers' margin).
            assert!((got - smallest).abs() < 1e-7 * 9.0, "{d:?}: {got}");
        }
        assert!(smallest_eigenvalue(&Mat3::from_element(Real::NAN)).is_nan());
    }
}
