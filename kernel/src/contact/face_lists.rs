//! Per-node lists of the master faces a slave node can reach, kept over
//! many sweeps and steps (a Verlet list for node-to-surface detection).
//!
//! A pass of [`crate::contact::pair::detect`] tries every slave node near
//! the pair's overlap against every master face near it: most of those
//! tests fail on the face's reach box (its box grown by the gap window).
//! The lists record, once, which faces each node could reach, on an
//! *anchor* configuration of both bodies, with a skin: while no surface
//! node of either body has moved more than `drift` from its anchor,
//! [`crate::contact::pair::detect_listed`] tries each node against its own
//! list only and finds **the same constraints, to the bit**, as the full
//! pass (the faces left out are the ones every test of the full pass
//! skips, and the faces kept are tried in the same ascending order).
//!
//! Why the skin is enough: the full pass uses a face O for a node p only
//! (a) when O's reach — its box grown by its window g_O = f·diag_O —
//! holds p (the hit search and the concave-edge search), or (b) when O's
//! box is nearer to p than the depth of another face's hit (the "nearer
//! face" check), a depth below *that* face's window. Both are within
//! G = f × the master's largest face diagonal of O's box. If every corner
//! moved at most d, a box grew by at most d and a diagonal by at most 2d,
//! so G grew by at most 2f·d; the slave node moved at most d too. A face
//! is therefore listed for a node when the node's anchor lies in the
//! face's anchor box grown by τ = G_anchor + (2 + 2f)·d (times 1 + 1e-6
//! against round-off). (Growing each box by its own window instead is not
//! enough: a small face can overrule the hit on a larger one.)
//!
//! Buffers (caller-owned, see [`FaceListsMut`]): `nodes` (slave node ids
//! with at least one face, ascending), `starts` (`nodes.len() + 1`
//! offsets into `faces`), `faces` (master quad ids, ascending per node),
//! `used` (every quad that is in some list, ascending).

use crate::Real;
use crate::contact::pair::ContactError;
use crate::contact::quad::Vec3;
use crate::contact::surface::Aabb;

/// A body's surface on its anchor configuration.
#[derive(Clone, Copy, Debug)]
pub struct AnchorSurface<'a> {
    /// Positions of the surface nodes only: node `first_surface + i` is
    /// `x[i]`, m.
    pub x: &'a [Vec3],
    /// Index of the first surface node in the body's node numbering.
    pub first_surface: usize,
    /// Outer quads (global node ids, all ≥ `first_surface`).
    pub quads: &'a [[u32; 4]],
}

/// Read view of one pass's lists (slave → master).
#[derive(Clone, Copy, Debug, Default)]
pub struct FaceLists<'a> {
    /// Slave node ids (global numbering) with at least one face, ascending.
    pub nodes: &'a [u32],
    /// `faces[starts[k]..starts[k + 1]]` belong to `nodes[k]`; length
    /// `nodes.len() + 1`.
    pub starts: &'a [u32],
    /// Master quad ids, ascending within each node's range.
    pub faces: &'a [u32],
    /// Every master quad that is in some list, ascending.
    pub used: &'a [u32],
}

impl<'a> FaceLists<'a> {
    /// The faces listed for the `k`-th node of `nodes` (none for a `k` past
    /// the lists or offsets that [`Self::check`] refuses).
    pub fn faces_of(&self, k: usize) -> &'a [u32] {
        let range =
            |k: usize| Some(*self.starts.get(k)? as usize..*self.starts.get(k + 1)? as usize);
        range(k).and_then(|r| self.faces.get(r)).unwrap_or(&[])
    }

    /// Checks the layout: one offset per node and one more, non-decreasing,
    /// the last within `faces`, and `used` strictly ascending — what
    /// [`build`] writes. (The detection checks the node and used-quad ids
    /// where it reads them; a listed face id outside the master's quads is
    /// no candidate. Ascending ids below the master's quad count are at
    /// most that many, which the detection's scratch holds.)
    ///
    /// Errors: `starts` not one longer than `nodes`, or `faces` shorter
    /// than the last offset ([`ContactError::BufferLength`]); an offset
    /// below the one before, or a used id not above the one before
    /// ([`ContactError::InvalidParameter`], with the index in `starts` or
    /// `used` as the value).
    pub fn check(&self) -> Result<(), ContactError> {
        if self.starts.len() != self.nodes.len() + 1 {
            return Err(ContactError::BufferLength {
                buffer: "face lists (starts)",
                expected: self.nodes.len() + 1,
                got: self.starts.len(),
            });
        }
        if let Some(k) = self.starts.windows(2).position(|w| w[1] < w[0]) {
            return Err(ContactError::InvalidParameter {
                field: "face lists (starts): index of a decreasing offset",
                value: (k + 1) as Real,
                allowed: "non-decreasing offsets",
            });
        }
        if let Some(k) = self.used.windows(2).position(|w| w[1] <= w[0]) {
            return Err(ContactError::InvalidParameter {
                field: "face lists (used): index of an id not above the one before",
                value: (k + 1) as Real,
                allowed: "strictly ascending quad ids",
            });
        }
        match self.starts.last() {
            Some(&end) if end as usize > self.faces.len() => Err(ContactError::BufferLength {
                buffer: "face lists (faces)",
                expected: end as usize,
                got: self.faces.len(),
            }),
            _ => Ok(()),
        }
    }
}

/// The caller's buffers [`build`] writes one pass's lists into.
#[derive(Debug)]
pub struct FaceListsMut<'a> {
    /// Capacity: the slave's surface node count is always enough.
    pub nodes: &'a mut [u32],
    /// Capacity: one more than `nodes`.
    pub starts: &'a mut [u32],
    /// Capacity: grow and retry on [`ContactError::Capacity`].
    pub faces: &'a mut [u32],
    /// Capacity: the master's quad count is always enough.
    pub used: &'a mut [u32],
}

/// Lengths [`build`] filled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListLengths {
    /// Entries of `nodes` (and `nodes + 1` of `starts`).
    pub nodes: usize,
    /// Entries of `faces`.
    pub faces: usize,
    /// Entries of `used`.
    pub used: usize,
}

/// One master face on the anchor: its quad id and its box grown by τ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReachBox {
    /// Quad id in the master body.
    pub quad: u32,
    /// Anchor box grown by τ (module docs).
    pub reach: Aabb,
    /// Whether some slave node listed it.
    pub used: bool,
}

impl Default for ReachBox {
    fn default() -> Self {
        Self {
            quad: 0,
            reach: Aabb::EMPTY,
            used: false,
        }
    }
}

/// Builds the lists of the pass `slave` → `master` on their anchors, valid
/// while no surface node of either body is farther than `drift` (m, finite,
/// ≥ 0) from its anchor. `window_fraction` is the pair's f (g_max = f ×
/// face diagonal; finite, ≥ 0). `scratch` needs one entry per master quad.
/// A full `faces` buffer is [`ContactError::Capacity`] (grow it and call
/// again); a NaN, negative or infinite `drift` or `window_fraction` is
/// [`ContactError::InvalidParameter`] (with a NaN the lists came out empty
/// and the detection through them missed every contact without a word).
pub fn build(
    slave: &AnchorSurface<'_>,
    master: &AnchorSurface<'_>,
    window_fraction: Real,
    drift: Real,
    scratch: &mut [ReachBox],
    out: FaceListsMut<'_>,
) -> Result<ListLengths, ContactError> {
    for (field, value) in [("drift", drift), ("window_fraction", window_fraction)] {
        if !(value >= 0.0 && value.is_finite()) {
            return Err(ContactError::InvalidParameter {
                field,
                value,
                allowed: "finite, >= 0",
            });
        }
    }
    check_len("scratch", scratch.len(), master.quads.len())?;
    check_len("nodes", out.nodes.len(), slave.x.len())?;
    check_len("starts", out.starts.len(), slave.x.len() + 1)?;
    check_len("used", out.used.len(), master.quads.len())?;
    let slave_box = Aabb::of_points(slave.x);
    // The master's largest face diagonal (a face with a NaN corner has a
    // NaN box, which no test of the full pass accepts: it does not count).
    let mut largest: Real = 0.0;
    for quad in master.quads {
        if let Some(c) = master.corners(quad) {
            let diagonal = face_diagonal(&c);
            if diagonal > largest {
                largest = diagonal;
            }
        }
    }
    let tau = (window_fraction * largest + (2.0 + 2.0 * window_fraction) * drift) * (1.0 + 1e-6);
    let mut candidates = 0;
    let mut reach_all = Aabb::EMPTY;
    for (q, quad) in master.quads.iter().enumerate() {
        let Some(corners) = master.corners(quad) else {
            continue;
        };
        let reach = Aabb::of_points(&corners).expanded(tau);
        if reach.overlaps(&slave_box) {
            scratch[candidates] = ReachBox {
                quad: q as u32,
                reach,
                used: false,
            };
            candidates += 1;
            reach_all = reach_all.with(&reach.lo).with(&reach.hi);
        }
    }
    let scratch = &mut scratch[..candidates];
    let mut len = ListLengths::default();
    for (i, p) in slave.x.iter().enumerate() {
        if !reach_all.contains(p) {
            continue;
        }
        let start = len.faces;
        for c in scratch.iter_mut() {
            if c.reach.contains(p) {
                let slot = out.faces.get_mut(len.faces).ok_or(ContactError::Capacity {
                    buffer: "face lists",
                    capacity: len.faces,
                })?;
                *slot = c.quad;
                len.faces += 1;
                c.used = true;
            }
        }
        if len.faces > start {
            out.nodes[len.nodes] = (slave.first_surface + i) as u32;
            out.starts[len.nodes] = start as u32;
            len.nodes += 1;
        }
    }
    out.starts[len.nodes] = len.faces as u32;
    for c in scratch.iter().filter(|c| c.used) {
        out.used[len.used] = c.quad;
        len.used += 1;
    }
    Ok(len)
}

impl AnchorSurface<'_> {
    /// The anchor corners of `quad` (`None` if a corner is not a surface
    /// node of this body).
    fn corners(&self, quad: &[u32; 4]) -> Option<[Vec3; 4]> {
        let mut c = [[0.0; 3]; 4];
        for (ck, &id) in c.iter_mut().zip(quad) {
            *ck = *self.x.get((id as usize).checked_sub(self.first_surface)?)?;
        }
        Some(c)
    }
}

/// Largest face diagonal of quad `x`, m (as the detection's window uses).
pub fn face_diagonal(x: &[Vec3; 4]) -> Real {
    use crate::contact::quad::{norm, sub};
    let d1 = norm(&sub(&x[2], &x[0]));
    let d2 = norm(&sub(&x[3], &x[1]));
    if d1 > d2 { d1 } else { d2 }
}

/// [`ContactError::BufferLength`] when `got` < `expected`.
pub(crate) fn check_len(
    buffer: &'static str,
    got: usize,
    expected: usize,
) -> Result<(), ContactError> {
    if got < expected {
        Err(ContactError::BufferLength {
            buffer,
            expected,
            got,
        })
    } else {
        Ok(())
    }
}

/// The largest distance, m, of a surface node in `x[first_surface..]`
/// from its anchor (`anchor[i]` for node `first_surface + i`); NaN if a
/// position is NaN or the lengths differ (renew the anchor then).
pub fn drift(x: &[Vec3], first_surface: usize, anchor: &[Vec3]) -> Real {
    let Some(surface) = x.get(first_surface..) else {
        return Real::NAN;
    };
    if surface.len() != anchor.len() {
        return Real::NAN;
    }
    let mut worst: Real = 0.0;
    for (p, a) in surface.iter().zip(anchor) {
        let d2 = (p[0] - a[0]) * (p[0] - a[0])
            + (p[1] - a[1]) * (p[1] - a[1])
            + (p[2] - a[2]) * (p[2] - a[2]);
        if d2.is_nan() {
            return Real::NAN;
        }
        if d2 > worst {
            worst = d2;
        }
    }
    crate::math::sqrt(worst)
}
