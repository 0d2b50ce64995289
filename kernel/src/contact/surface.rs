//! A deforming body's surface as the contact passes see it: node buffers of
//! one granule plus the shared surface topology of its reference mesh, and
//! the axis-aligned boxes used to narrow a pair's work (physics.md §5.1).

use crate::Real;
use crate::contact::broad::Bound;
use crate::contact::quad::{Vec3, cross, norm, sub};
use crate::math::{max, min};

/// One granule's surface on the predicted configuration.
///
/// Node buffers (`x_n`, `x_pred`, `mass`) have one entry per node of the
/// mesh; surface nodes are the last ones, from `first_surface` on.
/// `quads` are the outer quads (global node ids, counter-clockwise seen
/// from outside); `node_quads[s]` lists the quads of surface node
/// `first_surface + s` (`u32::MAX` marks an unused slot).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceBody<'a> {
    /// Positions at t_n, m.
    pub x_n: &'a [Vec3],
    /// Predicted positions at t_{n+1}, m.
    pub x_pred: &'a [Vec3],
    /// Lumped nodal masses, kg.
    pub mass: &'a [Real],
    /// Index of the first surface node.
    pub first_surface: usize,
    /// Outer surface quads.
    pub quads: &'a [[u32; 4]],
    /// Quads of each surface node.
    pub node_quads: &'a [[u32; 4]],
    /// Box of the predicted surface nodes ([`Aabb::of_surface`]).
    pub bounds: Aabb,
    /// Bounding sphere of the predicted surface nodes
    /// ([`crate::contact::broad::bounding_sphere`]).
    pub sphere: Bound,
    /// Box of each quad's predicted corners ([`quad_bounds`]), one per quad:
    /// computed once per configuration searched and shared by all the
    /// body's pairs. Only the detection reads this and `bounds`; the forces
    /// and [`crate::contact::pair::regap`] do not.
    pub quad_bounds: &'a [Aabb],
}

/// Fills `out` (one entry per quad) with the box of each quad's corners
/// in `x`.
pub fn quad_bounds(x: &[Vec3], quads: &[[u32; 4]], out: &mut [Aabb]) {
    for (b, q) in out.iter_mut().zip(quads) {
        *b = Aabb::of_points(q.iter().map(|&i| &x[i as usize]));
    }
}

impl SurfaceBody<'_> {
    /// Corner positions of quad `q` on the predicted configuration.
    pub fn quad_pred(&self, q: usize) -> [Vec3; 4] {
        self.quads[q].map(|i| self.x_pred[i as usize])
    }

    /// Tributary area of surface node `node` on the predicted
    /// configuration: a quarter of the areas of its quads, m².
    pub fn node_area(&self, node: usize) -> Real {
        self.node_quads[node - self.first_surface]
            .iter()
            .filter(|&&q| q != u32::MAX)
            .map(|&q| 0.25 * crate::mesh::surface::quad_area(&self.quad_pred(q as usize)))
            .sum()
    }

    /// Averaged outward normal (not normalised; zero if degenerate) of
    /// surface node `node` on the predicted configuration: the sum of the
    /// area vectors of its quads.
    pub fn node_normal(&self, node: usize) -> Vec3 {
        let mut n = [0.0; 3];
        for &q in &self.node_quads[node - self.first_surface] {
            if q == u32::MAX {
                continue;
            }
            let x = self.quad_pred(q as usize);
            let a = cross(&sub(&x[2], &x[0]), &sub(&x[3], &x[1]));
            for k in 0..3 {
                n[k] += a[k];
            }
        }
        n
    }
}

/// An axis-aligned box; empty when any `lo > hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner, m.
    pub lo: Vec3,
    /// Upper corner, m.
    pub hi: Vec3,
}

impl Aabb {
    /// The empty box.
    pub const EMPTY: Aabb = Aabb {
        lo: [Real::INFINITY; 3],
        hi: [Real::NEG_INFINITY; 3],
    };

    /// The box of `points`.
    pub fn of_points<'p>(points: impl IntoIterator<Item = &'p Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.with(p))
    }

    /// The box of the surface nodes `x[first_surface..]`.
    pub fn of_surface(x: &[Vec3], first_surface: usize) -> Self {
        Self::of_points(x.get(first_surface..).unwrap_or(&[]))
    }

    /// This box grown to hold `p`.
    pub fn with(self, p: &Vec3) -> Self {
        Self {
            lo: core::array::from_fn(|a| min(self.lo[a], p[a])),
            hi: core::array::from_fn(|a| max(self.hi[a], p[a])),
        }
    }

    /// This box grown by `margin` on every side.
    pub fn expanded(self, margin: Real) -> Self {
        Self {
            lo: self.lo.map(|c| c - margin),
            hi: self.hi.map(|c| c + margin),
        }
    }

    /// The intersection (possibly empty).
    pub fn intersect(&self, other: &Aabb) -> Self {
        Self {
            lo: core::array::from_fn(|a| max(self.lo[a], other.lo[a])),
            hi: core::array::from_fn(|a| min(self.hi[a], other.hi[a])),
        }
    }

    /// True if the box holds no point.
    pub fn is_empty(&self) -> bool {
        (0..3).any(|a| self.lo[a] > self.hi[a] || self.lo[a].is_nan() || self.hi[a].is_nan())
    }

    /// True if `p` is inside (boundary included).
    pub fn contains(&self, p: &Vec3) -> bool {
        (0..3).all(|a| self.lo[a] <= p[a] && p[a] <= self.hi[a])
    }

    /// True if the boxes share a point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        (0..3).all(|a| self.lo[a] <= other.hi[a] && other.lo[a] <= self.hi[a])
    }

    /// Distance from `p` to the box (0 inside), m.
    pub fn distance_to(&self, p: &Vec3) -> Real {
        let d: Vec3 = core::array::from_fn(|a| max(0.0, max(self.lo[a] - p[a], p[a] - self.hi[a])));
        norm(&d)
    }

    /// Length of the diagonal, m (0 for an empty box).
    pub fn diagonal(&self) -> Real {
        if self.is_empty() {
            0.0
        } else {
            norm(&sub(&self.hi, &self.lo))
        }
    }
}
