//! A deforming body's surface as the contact passes see it: node buffers of
//! one granule plus the shared surface topology of its reference mesh, and
//! the axis-aligned boxes used to narrow a pair's work (physics.md §5.1).

use crate::Real;
use crate::contact::broad::Bound;
use crate::contact::pair::ContactError;
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
/// in `x`. A quad naming a node outside `x` gets the unbounded box (no
/// panic): the detection then takes it as a candidate, reads its corners
/// and reports the id ([`crate::contact::pair::ContactError::IdOutOfRange`]).
pub fn quad_bounds(x: &[Vec3], quads: &[[u32; 4]], out: &mut [Aabb]) {
    for (b, q) in out.iter_mut().zip(quads) {
        *b = match q.map(|i| x.get(i as usize)) {
            [Some(p0), Some(p1), Some(p2), Some(p3)] => Aabb::of_points([p0, p1, p2, p3]),
            _ => Aabb::UNBOUNDED,
        };
    }
}

/// [`ContactError::IdOutOfRange`] for `id`, read from entry `index` of
/// `buffer`, that indexes a buffer of `len` entries.
fn out_of_range(buffer: &'static str, index: usize, id: usize, len: usize) -> ContactError {
    ContactError::IdOutOfRange {
        buffer,
        index,
        id: u32::try_from(id).unwrap_or(u32::MAX),
        len,
    }
}

impl SurfaceBody<'_> {
    /// Corner positions of quad `q` on the predicted configuration;
    /// `None` if `q` is not a quad or a corner not a node of `x_pred`
    /// (the cheap form of [`Self::quad_pred`] for the detection's loops).
    #[inline]
    pub(crate) fn corners(&self, q: usize) -> Option<[Vec3; 4]> {
        let quad = self.quads.get(q)?;
        let x = |i: usize| self.x_pred.get(quad[i] as usize).copied();
        Some([x(0)?, x(1)?, x(2)?, x(3)?])
    }

    /// Corner positions of quad `q` on the predicted configuration; an
    /// error ([`ContactError::IdOutOfRange`]) if `q` is not a quad or a
    /// corner not a node of `x_pred`.
    pub fn quad_pred(&self, q: usize) -> Result<[Vec3; 4], ContactError> {
        self.corners(q).ok_or_else(|| self.quad_error(q))
    }

    /// Why [`Self::corners`] of `q` is `None`.
    #[cold]
    #[inline(never)]
    pub(crate) fn quad_error(&self, q: usize) -> ContactError {
        let Some(quad) = self.quads.get(q) else {
            return out_of_range("quad id", q, q, self.quads.len());
        };
        let n = self.x_pred.len();
        let id = quad.iter().find(|&&id| id as usize >= n).copied();
        out_of_range("quads", q, id.map_or(usize::MAX, |id| id as usize), n)
    }

    /// The corners of each quad of surface node `node` (`u32::MAX`
    /// slots skipped) to `f`; `None` if `node` has no `node_quads` entry
    /// or an id there or in a quad is outside its buffer.
    #[inline]
    fn each_quad(&self, node: usize, mut f: impl FnMut(&[Vec3; 4])) -> Option<()> {
        let quads = self.node_quads.get(node.checked_sub(self.first_surface)?)?;
        for &q in quads {
            if q != u32::MAX {
                f(&self.corners(q as usize)?);
            }
        }
        Some(())
    }

    /// Why [`Self::each_quad`] of `node` is `None`.
    #[cold]
    #[inline(never)]
    fn node_error(&self, node: usize) -> ContactError {
        let s = node
            .checked_sub(self.first_surface)
            .filter(|&s| s < self.node_quads.len());
        let Some(s) = s else {
            return out_of_range(
                "surface node id (first_surface + index of node_quads)",
                node,
                node,
                self.first_surface + self.node_quads.len(),
            );
        };
        for &q in &self.node_quads[s] {
            if q == u32::MAX {
                continue;
            }
            if q as usize >= self.quads.len() {
                return out_of_range("node_quads", s, q as usize, self.quads.len());
            }
            if self.corners(q as usize).is_none() {
                return self.quad_error(q as usize);
            }
        }
        out_of_range("node_quads", s, usize::MAX, self.quads.len())
    }

    /// Tributary area of surface node `node` on the predicted
    /// configuration: a quarter of the areas of its quads, m². An error
    /// ([`ContactError::IdOutOfRange`]) for a node, quad or corner id
    /// outside its buffer.
    pub fn node_area(&self, node: usize) -> Result<Real, ContactError> {
        let mut area = 0.0;
        self.each_quad(node, |x| area += 0.25 * crate::mesh::surface::quad_area(x))
            .ok_or_else(|| self.node_error(node))?;
        Ok(area)
    }

    /// Averaged outward normal (not normalised; zero if degenerate) of
    /// surface node `node` on the predicted configuration (the sum of the
    /// area vectors of its quads); `None` for a node, quad or corner id
    /// outside its buffer (the detection's form of [`Self::node_normal`]).
    #[inline]
    pub(crate) fn try_node_normal(&self, node: usize) -> Option<Vec3> {
        let mut n = [0.0; 3];
        self.each_quad(node, |x| {
            let a = cross(&sub(&x[2], &x[0]), &sub(&x[3], &x[1]));
            for k in 0..3 {
                n[k] += a[k];
            }
        })?;
        Some(n)
    }

    /// Averaged outward normal (not normalised; zero if degenerate) of
    /// surface node `node` on the predicted configuration: the sum of the
    /// area vectors of its quads. An error
    /// ([`ContactError::IdOutOfRange`]) for a node, quad or corner id
    /// outside its buffer.
    pub fn node_normal(&self, node: usize) -> Result<Vec3, ContactError> {
        self.try_node_normal(node)
            .ok_or_else(|| self.node_error(node))
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

    /// The box of all space.
    pub const UNBOUNDED: Aabb = Aabb {
        lo: [Real::NEG_INFINITY; 3],
        hi: [Real::INFINITY; 3],
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
