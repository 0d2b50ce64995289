//! How deep a point lies inside a closed quad surface, by geometry alone:
//! an overlap measure independent of the contact detection.
//!
//! The detection (physics.md §5.2, [`crate::contact::pair`]) decides which
//! face holds a node with normals, projection windows and a nearest-face
//! rule; its own overlap figure is the deepest gap it found. Where its
//! decisions are wrong, a node can sink into a neighbour unseen and the
//! figure still reads zero (BENCHMARKS.md, "Overlaps the detection did not
//! see", session 43). The measure here uses none of those decisions:
//!
//! * *inside* is the generalised winding number of the closed surface
//!   about the point, w = Σ Ω_t / 4π over its triangles (Ω_t the signed
//!   solid angle of triangle t seen from the point, by the formula of Van
//!   Oosterom and Strackee, IEEE Trans. Biomed. Eng. 30, 1983): |w| = 1
//!   inside a closed surface, 0 outside, whatever the orientation of its
//!   faces; the point is inside where |w| > ½;
//! * *depth* is the distance from the point to the nearest triangle
//!   (closest point on a triangle: Ericson, Real-Time Collision Detection,
//!   2005, §5.1.5).
//!
//! Each bilinear quad is split into [`SUBDIVISIONS`]² sub-quads of two
//! triangles, at the bilinear map's points: the triangles lie on the quad's
//! surface at their corners, so the triangulated surface departs from the
//! bilinear one by about the quad's warp / [`SUBDIVISIONS`]². The edges of
//! a bilinear quad are straight, so the triangulated quads meet along them
//! and the surface stays closed. (With 4 subdivisions, the quads of a
//! coarse granule pressed to 60 % strain departed by up to 0.8 µm, 0.6 %
//! of its element; with 8 and 16 the deepest node agreed with the contact
//! detection's projection on the bilinear face to 1 % and 0.04 %.)
//!
//! Cost: one `atan2` and about 40 flops per triangle and point, with only
//! the quads near the point subdivided ([`winding_number`]); a driver tests
//! only points inside the other body's bounding box.

use crate::Real;
use crate::contact::quad::{Vec3, axpy, cross, dot, norm, sub};
use crate::contact::surface::Aabb;
use crate::math;

/// Sub-quads per quad edge.
pub const SUBDIVISIONS: usize = 16;

/// A quad names a node that the positions do not have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeOutOfRange {
    /// The quad (index into the quad list).
    pub quad: usize,
    /// The node id it names.
    pub node: u32,
}

impl core::fmt::Display for NodeOutOfRange {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "quad {} names node {}, beyond the positions",
            self.quad, self.node
        )
    }
}

impl core::error::Error for NodeOutOfRange {}

/// The signed solid angle of triangle (a, b, c) seen from `p`, sr:
/// positive where its normal (b − a) × (c − a) points away from `p` (the
/// triangle winds clockwise seen from `p`), so that the outward faces of a
/// closed surface give +4π about a point inside.
fn solid_angle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> Real {
    let (a, b, c) = (sub(a, p), sub(b, p), sub(c, p));
    let (la, lb, lc) = (norm(&a), norm(&b), norm(&c));
    let numerator = dot(&a, &cross(&b, &c));
    let denominator = la * lb * lc + dot(&a, &b) * lc + dot(&a, &c) * lb + dot(&b, &c) * la;
    2.0 * libm::atan2(numerator, denominator)
}

/// Distance from `p` to the triangle (a, b, c), m: to its closest point,
/// found by the Voronoi region of `p` (vertices, edges, face).
fn triangle_distance(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> Real {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(&ab, &ap), dot(&ac, &ap));
    let at = |q: Vec3| norm(&sub(p, &q));
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(*a);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(&ab, &bp), dot(&ac, &bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at(*b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(axpy(d1 / (d1 - d3), &ab, a));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(&ab, &cp), dot(&ac, &cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at(*c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(axpy(d2 / (d2 - d6), &ac, a));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let bc = sub(c, b);
        return at(axpy((d4 - d3) / ((d4 - d3) + (d5 - d6)), &bc, b));
    }
    let denominator = va + vb + vc;
    let (v, w) = (vb / denominator, vc / denominator);
    at([
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ])
}

/// The corners of quad `quad` (`q`, node ids into `x`).
fn corners(x: &[Vec3], quad: usize, q: &[u32; 4]) -> Result<[Vec3; 4], NodeOutOfRange> {
    let mut out = [[0.0; 3]; 4];
    for (corner, &node) in out.iter_mut().zip(q) {
        *corner = *x.get(node as usize).ok_or(NodeOutOfRange { quad, node })?;
    }
    Ok(out)
}

/// Calls `f` with the [`SUBDIVISIONS`]² × 2 triangles of the bilinear quad
/// with corners `c` (in the quad's order: (0,0), (1,0), (1,1), (0,1)).
fn fine_triangles(c: &[Vec3; 4], mut f: impl FnMut(&Vec3, &Vec3, &Vec3)) {
    const N: usize = SUBDIVISIONS;
    let point = |i: usize, j: usize| -> Vec3 {
        let (s, t) = (i as Real / N as Real, j as Real / N as Real);
        let w = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
        core::array::from_fn(|k| w[0] * c[0][k] + w[1] * c[1][k] + w[2] * c[2][k] + w[3] * c[3][k])
    };
    for i in 0..N {
        for j in 0..N {
            let (p00, p10, p11, p01) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            f(&p00, &p10, &p11);
            f(&p00, &p11, &p01);
        }
    }
}

/// The generalised winding number of the closed surface `quads` (node ids
/// into `x`, positions in m) about `p`: ±1 inside, 0 outside (the sign is
/// the faces' orientation), fractional only on the surface or where it is
/// not closed.
///
/// A quad whose corners' box does not hold `p` counts as its two corner
/// triangles, not its [`SUBDIVISIONS`]² × 2: the quad's boundary is the
/// same four straight edges either way, so the two surfaces differ by a
/// closed sliver inside that box, which winds zero times about a point
/// outside it. The winding number is the fine surface's, for the cost of
/// the coarse one and the few quads near `p`.
pub fn winding_number(p: &Vec3, x: &[Vec3], quads: &[[u32; 4]]) -> Result<Real, NodeOutOfRange> {
    let mut sum = 0.0;
    for (quad, q) in quads.iter().enumerate() {
        let c = corners(x, quad, q)?;
        if Aabb::of_points(&c).distance_to(p) > 0.0 {
            sum += solid_angle(p, &c[0], &c[1], &c[2]) + solid_angle(p, &c[0], &c[2], &c[3]);
        } else {
            fine_triangles(&c, |a, b, t| sum += solid_angle(p, a, b, t));
        }
    }
    Ok(sum / (4.0 * core::f64::consts::PI))
}

/// How deep `p` lies inside the closed surface `quads` at positions `x`,
/// m: its distance to the surface (the [`SUBDIVISIONS`]-fold triangulated
/// one; quads whose box is farther than the nearest triangle found so far
/// are skipped, which changes nothing) where the winding number's magnitude
/// exceeds ½, else 0; NaN where the winding number is (a position not
/// finite).
pub fn depth_inside(p: &Vec3, x: &[Vec3], quads: &[[u32; 4]]) -> Result<Real, NodeOutOfRange> {
    let w = winding_number(p, x, quads)?;
    if w.is_nan() {
        // A position that is not finite: no depth to give.
        return Ok(Real::NAN);
    }
    if math::abs(w) <= 0.5 {
        return Ok(0.0);
    }
    let mut nearest = Real::INFINITY;
    for (quad, q) in quads.iter().enumerate() {
        let c = corners(x, quad, q)?;
        if Aabb::of_points(&c).distance_to(p) >= nearest {
            continue;
        }
        fine_triangles(&c, |a, b, t| {
            nearest = math::min(nearest, triangle_distance(p, a, b, t));
        });
    }
    Ok(nearest)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube [0, 1]³ as six quads, outward counter-clockwise.
    fn cube() -> ([Vec3; 8], [[u32; 4]; 6]) {
        let x = core::array::from_fn(|i| {
            [
                (i & 1) as Real,
                ((i >> 1) & 1) as Real,
                ((i >> 2) & 1) as Real,
            ]
        });
        let quads = [
            [0, 2, 3, 1], // z = 0
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        (x, quads)
    }

    #[test]
    fn the_winding_number_is_one_inside_and_zero_outside() {
        let (x, q) = cube();
        for p in [[0.5, 0.5, 0.5], [0.01, 0.02, 0.99], [0.9, 0.1, 0.5]] {
            let w = winding_number(&p, &x, &q).unwrap();
            assert!((w - 1.0).abs() < 1e-12, "{p:?}: {w}");
        }
        for p in [[1.5, 0.5, 0.5], [-0.01, 0.5, 0.5], [3.0, -2.0, 7.0]] {
            let w = winding_number(&p, &x, &q).unwrap();
            assert!(w.abs() < 1e-12, "{p:?}: {w}");
        }
        // Reversed faces: −1 inside, and the depth does not care.
        let reversed = q.map(|[a, b, c, d]| [a, d, c, b]);
        let w = winding_number(&[0.5, 0.5, 0.5], &x, &reversed).unwrap();
        assert!((w + 1.0).abs() < 1e-12, "{w}");
        let d = depth_inside(&[0.5, 0.5, 0.3], &x, &reversed).unwrap();
        assert!((d - 0.3).abs() < 1e-15, "{d}");
    }

    #[test]
    fn the_depth_is_the_distance_to_the_nearest_face() {
        let (x, q) = cube();
        let cases = [
            ([0.5, 0.5, 0.4], 0.4),
            ([0.5, 0.97, 0.5], 0.03),
            ([0.2, 0.3, 0.25], 0.2),
            ([1.2, 0.5, 0.5], 0.0),
        ];
        for (p, want) in cases {
            let d = depth_inside(&p, &x, &q).unwrap();
            assert!((d - want).abs() < 1e-15, "{p:?}: {d} vs {want}");
        }
    }

    /// The closest point of a triangle in each of its seven Voronoi
    /// regions (three vertices, three edges, the face).
    #[test]
    fn the_triangle_distance_covers_every_region() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let cases = [
            ([-1.0, -1.0, 0.0], Real::sqrt(2.0)),
            ([3.0, -1.0, 0.0], Real::sqrt(2.0)),
            ([-1.0, 3.0, 0.0], Real::sqrt(2.0)),
            ([1.0, -1.0, 1.0], Real::sqrt(2.0)),
            ([-1.0, 1.0, 0.0], 1.0),
            ([2.0, 2.0, 0.0], Real::sqrt(2.0)),
            ([0.5, 0.5, -3.0], 3.0),
        ];
        for (p, want) in cases {
            let d = triangle_distance(&p, &a, &b, &c);
            assert!((d - want).abs() < 1e-15, "{p:?}: {d} vs {want}");
        }
    }

    /// A warped (non-planar) quad surface: the winding number of a closed
    /// surface is ±1 inside however its faces bend. A cube whose top is
    /// pushed down at one corner, probed just inside and outside there —
    /// and at z = 0.66, between the bilinear top (0.676 at x = y = 0.9) and
    /// its two corner triangles (0.64): inside, which only the subdivided
    /// face tells (with the corner triangles alone it reads 0).
    #[test]
    fn a_warped_closed_surface_still_winds_once() {
        let (mut x, q) = cube();
        x[7] = [1.0, 1.0, 0.6];
        for (p, want) in [
            ([0.9, 0.9, 0.55], 1.0),
            ([0.9, 0.9, 0.66], 1.0),
            ([0.9, 0.9, 0.75], 0.0),
        ] {
            let w = winding_number(&p, &x, &q).unwrap();
            assert!((w - want).abs() < 1e-12, "{p:?}: {w}");
        }
        let d = depth_inside(&[0.9, 0.9, 0.66], &x, &q).unwrap();
        assert!(d > 0.0 && d < 0.016, "{d}");
    }

    /// A position that is not finite gives NaN, not a plausible depth.
    #[test]
    fn a_non_finite_surface_gives_nan() {
        let (mut x, q) = cube();
        x[6][2] = Real::NAN;
        assert!(depth_inside(&[0.5; 3], &x, &q).unwrap().is_nan());
    }

    #[test]
    fn a_node_beyond_the_positions_is_an_error() {
        let (x, mut q) = cube();
        q[3][2] = 8;
        assert_eq!(
            winding_number(&[0.5; 3], &x, &q),
            Err(NodeOutOfRange { quad: 3, node: 8 })
        );
        assert!(depth_inside(&[0.5; 3], &x, &q).is_err());
    }
}
