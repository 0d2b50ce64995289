//! The 8-node trilinear hexahedron: node ordering, shape functions and their
//! derivatives (physics.md §2.1).
//!
//! Node I sits at the parent coordinates (ξ, η, ζ) = [`NODE_SIGNS`]`[I]`:
//! 0 (−,−,−), 1 (+,−,−), 2 (+,+,−), 3 (−,+,−), 4 (−,−,+), 5 (+,−,+),
//! 6 (+,+,+), 7 (−,+,+). N_I = ⅛(1 + ξξ_I)(1 + ηη_I)(1 + ζζ_I).

use crate::Real;
use crate::tensor::Mat3;

/// Node coordinates of one hex, `[node][xyz]`, m.
pub type HexCoords = [[Real; 3]; 8];

/// Parent-space signs (ξ_I, η_I, ζ_I) of the eight nodes.
pub const NODE_SIGNS: [[Real; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Node permutation that swaps the ξ and η directions (nodes 1↔3, 5↔7),
/// turning a left-handed node order right-handed.
pub const FLIP: [usize; 8] = [0, 3, 2, 1, 4, 7, 6, 5];

/// Abscissa of the 2-point Gauss rule on [−1, 1].
pub const GAUSS_2: Real = 0.577_350_269_189_625_8;

/// Shape function values N_I at (ξ, η, ζ).
#[inline]
pub fn shape(xi: [Real; 3]) -> [Real; 8] {
    core::array::from_fn(|i| {
        let s = NODE_SIGNS[i];
        0.125 * (1.0 + s[0] * xi[0]) * (1.0 + s[1] * xi[1]) * (1.0 + s[2] * xi[2])
    })
}

/// Parent-space gradients ∂N_I/∂(ξ, η, ζ) at (ξ, η, ζ). A `const fn`, so
/// that [`GAUSS_GRADIENTS`] is this function evaluated at compile time.
#[inline]
pub const fn shape_gradients(xi: [Real; 3]) -> [[Real; 3]; 8] {
    let mut out = [[0.0; 3]; 8];
    let mut i = 0;
    while i < 8 {
        let s = NODE_SIGNS[i];
        let a = 1.0 + s[0] * xi[0];
        let b = 1.0 + s[1] * xi[1];
        let c = 1.0 + s[2] * xi[2];
        out[i] = [
            0.125 * s[0] * b * c,
            0.125 * s[1] * a * c,
            0.125 * s[2] * a * b,
        ];
        i += 1;
    }
    out
}

/// [`shape_gradients`] at the eight [`gauss_points`], `[point][node][ξηζ]`,
/// evaluated at compile time (IEEE arithmetic, so the bits of the run-time
/// call): for loops over many elements at the Gauss points (quadrature,
/// the time-step estimate, the worst-element check), which otherwise took
/// the gradients afresh for every element.
pub const GAUSS_GRADIENTS: [[[Real; 3]; 8]; 8] = {
    let mut out = [[[0.0; 3]; 8]; 8];
    let mut g = 0;
    while g < 8 {
        out[g] = shape_gradients(gauss_point(g));
        g += 1;
    }
    out
};

/// Jacobian J_ij = ∂x_i/∂ξ_j of the trilinear map at (ξ, η, ζ).
#[inline]
pub fn jacobian(x: &HexCoords, xi: [Real; 3]) -> Mat3 {
    jacobian_from_gradients(x, &shape_gradients(xi))
}

/// [`jacobian`] from the parent-space gradients `g` =
/// [`shape_gradients`]`(ξ)`, for a caller that evaluates many elements at
/// the same point (the same bits).
#[inline(always)]
pub fn jacobian_from_gradients(x: &HexCoords, g: &[[Real; 3]; 8]) -> Mat3 {
    // Summed in rows of plain arrays (each entry over the nodes in order,
    // from zero: the bits of summing into the matrix), which the compiler
    // keeps in registers.
    let mut j = [[0.0; 3]; 3];
    for (xn, gn) in x.iter().zip(g.iter()) {
        for (jr, &xr) in j.iter_mut().zip(xn) {
            for (jrc, &gc) in jr.iter_mut().zip(gn) {
                *jrc += xr * gc;
            }
        }
    }
    crate::tensor::from_rows(&j)
}

/// The eight 2×2×2 Gauss points, in node order (point I near node I).
pub fn gauss_points() -> [[Real; 3]; 8] {
    core::array::from_fn(gauss_point)
}

/// Gauss point `i` of [`gauss_points`].
const fn gauss_point(i: usize) -> [Real; 3] {
    let s = NODE_SIGNS[i];
    [s[0] * GAUSS_2, s[1] * GAUSS_2, s[2] * GAUSS_2]
}

/// Scaled Jacobian at corner `i`: the determinant of the three unit edge
/// vectors leaving node `i` along +ξ, +η, +ζ (sign-corrected), in [−1, 1];
/// 1 for a cube corner, ≤ 0 for an inverted corner.
///
/// # Panics
/// If `i` ≥ 8 (a hex has eight corners).
pub fn corner_scaled_jacobian(x: &HexCoords, i: usize) -> Real {
    let j = jacobian(x, NODE_SIGNS[i]);
    let mut n = [0.0; 3];
    for (c, nc) in n.iter_mut().enumerate() {
        *nc = crate::math::sqrt(
            j[(0, c)] * j[(0, c)] + j[(1, c)] * j[(1, c)] + j[(2, c)] * j[(2, c)],
        );
    }
    crate::tensor::det_mat(&j) / (n[0] * n[1] * n[2])
}

/// Node slots of the six faces, each counter-clockwise seen from outside
/// for a right-handed hex.
pub const FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// Largest face area of the hex, m², each face taken as ½|d1 × d2| of its
/// diagonals (exact for planar faces). With the volume V it gives the
/// characteristic length L_e = V/A_max of the stable time step.
pub fn max_face_area(x: &HexCoords) -> Real {
    let mut max = 0.0;
    for f in FACES {
        let d1: [Real; 3] = core::array::from_fn(|a| x[f[2]][a] - x[f[0]][a]);
        let d2: [Real; 3] = core::array::from_fn(|a| x[f[3]][a] - x[f[1]][a]);
        let c = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        let area = 0.5 * crate::math::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        max = crate::math::max(max, area);
    }
    max
}
