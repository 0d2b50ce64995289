//! Broad phase of granule–granule contact (physics.md §5.1): each granule's
//! bounding sphere, a uniform grid over the centres, and the sorted list of
//! candidate pairs whose spheres come within a margin s.
//!
//! **Why the list stays valid (the skin).** A pair (A, B) left out at build
//! time had |c_A − c_B| ≥ r_A + r_B + s. If since then every granule's
//! drift |c − c_build| plus its radius growth max(0, r − r_build) stayed
//! below s/2 ([`needs_rebuild`]), the spheres of A and B still do not
//! overlap, so no node of A can be inside B: no contact is missed. The
//! driver rebuilds as soon as one granule breaks that bound.

use crate::Real;
use crate::contact::pair::ContactError;
use crate::contact::quad::{Vec3, dot, norm, sub};

/// A granule's bounding sphere: centroid of its surface nodes and the
/// largest distance of a surface node from it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bound {
    /// Centre, m.
    pub centre: Vec3,
    /// Radius, m.
    pub radius: Real,
}

/// The bounding sphere of the surface nodes `x[first_surface..]` (the zero
/// sphere if there are none).
pub fn bounding_sphere(x: &[Vec3], first_surface: usize) -> Bound {
    let surface = x.get(first_surface..).unwrap_or(&[]);
    if surface.is_empty() {
        return Bound::default();
    }
    let mut c = [0.0; 3];
    for p in surface {
        for a in 0..3 {
            c[a] += p[a];
        }
    }
    let inv = 1.0 / surface.len() as Real;
    let centre = c.map(|v| v * inv);
    // max |p − c| as √(max |p − c|²): a correctly rounded square root is
    // monotone, so this is the same number with one root instead of one
    // per node.
    let radius_squared = surface.iter().fold(0.0, |r, p| {
        let d = sub(p, &centre);
        crate::math::max(r, dot(&d, &d))
    });
    Bound {
        centre,
        radius: crate::math::sqrt(radius_squared),
    }
}

/// A candidate pair of granules, a < b.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct GranulePair {
    /// First granule.
    pub a: u32,
    /// Second granule.
    pub b: u32,
}

/// Scratch of [`candidate_pairs`]: `head` has one entry per grid cell (the
/// grid coarsens itself to fit; give it at least 8 × granules), `next` one
/// per granule.
pub struct BroadScratch<'a> {
    /// First granule of each cell's chain.
    pub head: &'a mut [u32],
    /// Next granule in the same cell.
    pub next: &'a mut [u32],
}

/// Most partners one granule may have in the list; a denser neighbourhood
/// is reported as [`ContactError::Capacity`].
pub const MAX_PARTNERS: usize = 64;

/// Writes the pairs (a < b, sorted) whose bounding spheres come within
/// `margin` (|c_a − c_b| < r_a + r_b + margin) to `out` and returns their
/// number.
pub fn candidate_pairs(
    bounds: &[Bound],
    margin: Real,
    scratch: &mut BroadScratch<'_>,
    out: &mut [GranulePair],
) -> Result<usize, ContactError> {
    let n = bounds.len();
    if scratch.next.len() < n || scratch.head.is_empty() {
        return Err(ContactError::BufferLength {
            buffer: "broad-phase scratch",
            expected: n.max(1),
            got: scratch.next.len().min(scratch.head.len()),
        });
    }
    let grid = CellGrid::new(bounds, margin, scratch.head.len());
    let (head, next) = (&mut *scratch.head, &mut *scratch.next);
    head.fill(u32::MAX);
    // Insert in reverse so each chain runs in increasing index order.
    for (i, b) in bounds.iter().enumerate().rev() {
        let c = grid.index(grid.cell_of(&b.centre));
        next[i] = head[c];
        head[c] = i as u32;
    }
    let mut count = 0;
    let full = ContactError::Capacity {
        buffer: "granule pairs",
        capacity: out.len(),
    };
    for (i, bi) in bounds.iter().enumerate() {
        let ci = grid.cell_of(&bi.centre);
        let mut partners: heapless::Vec<u32, MAX_PARTNERS> = heapless::Vec::new();
        for c in grid.neighbours(ci) {
            let mut j = head[grid.index(c)];
            while j != u32::MAX {
                let bj = &bounds[j as usize];
                if (j as usize) > i
                    && norm(&sub(&bj.centre, &bi.centre)) < bi.radius + bj.radius + margin
                {
                    let at = partners
                        .iter()
                        .position(|&k| k > j)
                        .unwrap_or(partners.len());
                    partners.insert(at, j).map_err(|_| ContactError::Capacity {
                        buffer: "partners per granule",
                        capacity: MAX_PARTNERS,
                    })?;
                }
                j = next[j as usize];
            }
        }
        for &j in &partners {
            *out.get_mut(count).ok_or(full)? = GranulePair { a: i as u32, b: j };
            count += 1;
        }
    }
    Ok(count)
}

/// True when some granule has drifted or grown by half the margin since
/// the list was built from `built` (same order as `now`).
pub fn needs_rebuild(built: &[Bound], now: &[Bound], margin: Real) -> bool {
    built.len() != now.len()
        || built.iter().zip(now).any(|(b, c)| {
            norm(&sub(&c.centre, &b.centre)) + crate::math::max(0.0, c.radius - b.radius)
                >= 0.5 * margin
        })
}

/// A uniform grid over the box of the centres with cells no smaller than
/// the largest search distance 2 r_max + margin.
struct CellGrid {
    origin: Vec3,
    cell: Real,
    dims: [usize; 3],
}

impl CellGrid {
    fn new(bounds: &[Bound], margin: Real, max_cells: usize) -> Self {
        let mut lo = [Real::INFINITY; 3];
        let mut hi = [Real::NEG_INFINITY; 3];
        let mut r_max: Real = 0.0;
        for b in bounds {
            for a in 0..3 {
                lo[a] = crate::math::min(lo[a], b.centre[a]);
                hi[a] = crate::math::max(hi[a], b.centre[a]);
            }
            r_max = crate::math::max(r_max, b.radius);
        }
        if bounds.is_empty() || !lo.iter().chain(&hi).all(|c| c.is_finite()) {
            return Self {
                origin: [0.0; 3],
                cell: Real::INFINITY,
                dims: [1; 3],
            };
        }
        let mut cell = crate::math::max(2.0 * r_max + margin, Real::MIN_POSITIVE);
        loop {
            let dims: [usize; 3] = core::array::from_fn(|a| {
                let k = libm::floor((hi[a] - lo[a]) / cell) + 1.0;
                if k < 1.0 { 1 } else { k as usize }
            });
            if dims
                .iter()
                .try_fold(1usize, |p, &d| p.checked_mul(d))
                .is_some_and(|p| p <= max_cells)
            {
                return Self {
                    origin: lo,
                    cell,
                    dims,
                };
            }
            cell *= 2.0;
        }
    }

    fn cell_of(&self, x: &Vec3) -> [usize; 3] {
        core::array::from_fn(|a| {
            let k = libm::floor((x[a] - self.origin[a]) / self.cell);
            if k.is_nan() || k < 0.0 {
                0
            } else {
                (k as usize).min(self.dims[a] - 1)
            }
        })
    }

    fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The up to 27 cells around `c` (inside the grid).
    fn neighbours(&self, c: [usize; 3]) -> impl Iterator<Item = [usize; 3]> + '_ {
        let range = move |a: usize| c[a].saturating_sub(1)..=(c[a] + 1).min(self.dims[a] - 1);
        range(2).flat_map(move |z| range(1).flat_map(move |y| range(0).map(move |x| [x, y, z])))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The radius is the largest node distance, taken as one root of the
    /// largest squared distance: the bits of the largest root.
    #[test]
    fn the_radius_is_the_largest_distance_to_the_bit() {
        let mut rng = Rng::new(7);
        let mut x = [[0.0; 3]; 64];
        for cloud in 0..2000 {
            let scale = 10f64.powi(cloud % 9 - 6);
            for p in &mut x {
                *p = core::array::from_fn(|_| scale * rng.uniform(-1.0, 1.0));
            }
            let first = cloud as usize % 8;
            let b = bounding_sphere(&x, first);
            let largest = x[first..]
                .iter()
                .fold(0.0, |r, p| crate::math::max(r, norm(&sub(p, &b.centre))));
            assert_eq!(b.radius.to_bits(), largest.to_bits(), "cloud {cloud}");
        }
    }
}
