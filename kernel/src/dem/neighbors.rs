//! Candidate contact pairs of equal spheres in a cylindrical die, found with
//! a uniform cell grid and kept for as long as no sphere has moved more than
//! half the skin (physics.md §6; the list is O(N) to build).
//!
//! A pair is (i, j) with i < j a sphere index, or j = [`FLOOR`] / [`DIE`]
//! for the walls. Pairs are sorted by (i, j), so forces are summed in a
//! fixed order and the tangential history moves to the next list by a
//! merge.

use core::fmt;

use crate::Real;

/// Pair partner meaning the die floor z = 0.
pub const FLOOR: u32 = u32::MAX - 1;
/// Pair partner meaning the cylindrical die wall.
pub const DIE: u32 = u32::MAX;

/// A candidate contact and its tangential spring history.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair {
    /// First sphere.
    pub i: u32,
    /// Second sphere (> i), or [`FLOOR`] / [`DIE`].
    pub j: u32,
    /// Tangential spring history ξ, m.
    pub xi: [Real; 3],
}

/// Partners (spheres j > i within range) one sphere can have in the pair
/// search's on-stack list.
pub const MAX_PARTNERS: usize = 64;

/// The pair list outgrew the buffer it was given, or one sphere's partners
/// outgrew [`MAX_PARTNERS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairOverflow {
    /// Capacity of the pair buffer, or [`MAX_PARTNERS`] if `per_sphere`.
    pub capacity: usize,
    /// One sphere had more than [`MAX_PARTNERS`] partners: a larger pair
    /// buffer does not help (spheres overlap far more than a pour allows,
    /// or the search range is too long for the radius).
    pub per_sphere: bool,
}

impl fmt::Display for PairOverflow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.per_sphere {
            write!(
                f,
                "contact pair list overflow: a sphere has more than {} partners within the \
                 search range (deeply overlapping spheres, or a skin longer than the radius)",
                self.capacity
            )
        } else {
            write!(
                f,
                "contact pair list overflow: more than {} candidate pairs",
                self.capacity
            )
        }
    }
}

impl core::error::Error for PairOverflow {}

/// The uniform grid over the die: square cells of side ≥ the search range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Cell side, m.
    pub cell: Real,
    /// Cells along x and y (the die's bounding square).
    pub nxy: usize,
    /// Cells along z, from z = 0 up (higher spheres go to the top layer).
    pub nz: usize,
    /// Half-width of the bounding square (the die radius), m.
    pub half_width: Real,
}

impl Grid {
    /// A grid over a die of radius `die_radius` (m) up to `height` (m) with
    /// cells of at least `range` (m).
    pub fn new(die_radius: Real, height: Real, range: Real) -> Self {
        let nxy = crate::math::max(1.0, libm::floor(2.0 * die_radius / range)) as usize;
        let cell = 2.0 * die_radius / nxy as Real;
        let nz = crate::math::max(1.0, libm::ceil(height / cell)) as usize;
        Self {
            cell,
            nxy,
            nz,
            half_width: die_radius,
        }
    }

    /// Number of cells (the length of the `head` buffer); `usize::MAX` if
    /// that does not fit (no buffer can hold it, so no pour starts).
    pub fn cells(&self) -> usize {
        self.nxy
            .checked_mul(self.nxy)
            .and_then(|layer| layer.checked_mul(self.nz))
            .unwrap_or(usize::MAX)
    }

    fn coord(&self, c: Real, n: usize) -> usize {
        let k = libm::floor(c / self.cell);
        if k.is_nan() || k < 0.0 {
            0
        } else {
            (k as usize).min(n - 1)
        }
    }

    fn cell_of(&self, x: &[Real; 3]) -> [usize; 3] {
        [
            self.coord(x[0] + self.half_width, self.nxy),
            self.coord(x[1] + self.half_width, self.nxy),
            self.coord(x[2], self.nz),
        ]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.nxy * (c[1] + self.nxy * c[2])
    }
}

/// Scratch of the pour's candidate search (`build_pairs`): one `head` entry per grid cell
/// ([`Grid::cells`]), one `next` entry per sphere.
pub struct GridScratch<'a> {
    /// First sphere of each cell's chain.
    pub head: &'a mut [u32],
    /// Next sphere in the same cell.
    pub next: &'a mut [u32],
}

/// Builds the sorted candidate list into `out` and returns its length:
/// sphere pairs closer than `range` (centre distance) and spheres closer
/// than the skin `range − 2·radius` to the floor or the die wall. The
/// tangential history of pairs present in `old` (sorted) is carried over.
///
/// Crate-private: it indexes `scratch.head` by `grid`'s cells and
/// `scratch.next` by sphere without checking their lengths, which
/// [`crate::dem::pour::PourScene`] checks once when it starts.
pub(crate) fn build_pairs(
    grid: &Grid,
    x: &[[Real; 3]],
    radius: Real,
    range: Real,
    scratch: &mut GridScratch<'_>,
    old: &[Pair],
    out: &mut [Pair],
) -> Result<usize, PairOverflow> {
    let (head, next) = (&mut *scratch.head, &mut *scratch.next);
    head.fill(u32::MAX);
    // Insert in reverse so each cell's chain runs in increasing index order.
    for (i, p) in x.iter().enumerate().rev() {
        let c = grid.index(grid.cell_of(p));
        next[i] = head[c];
        head[c] = i as u32;
    }
    let wall_gap = range - 2.0 * radius; // the skin
    let overflow = PairOverflow {
        capacity: out.len(),
        per_sphere: false,
    };
    let crowded = PairOverflow {
        capacity: MAX_PARTNERS,
        per_sphere: true,
    };
    let mut count = 0;
    let mut o = 0; // merge cursor in `old`
    let range2 = range * range;
    for (i, p) in x.iter().enumerate() {
        let ci = grid.cell_of(p);
        // Collect this sphere's partners j > i in increasing order: scan the
        // 27 neighbour cells (each chain is sorted) and insert-sort a small
        // on-stack buffer.
        let mut partners: heapless::Vec<u32, MAX_PARTNERS> = heapless::Vec::new();
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let c = [ci[0] as i64 + dx, ci[1] as i64 + dy, ci[2] as i64 + dz];
                    if c[0] < 0
                        || c[1] < 0
                        || c[2] < 0
                        || c[0] >= grid.nxy as i64
                        || c[1] >= grid.nxy as i64
                        || c[2] >= grid.nz as i64
                    {
                        continue;
                    }
                    let mut j = head[grid.index([c[0] as usize, c[1] as usize, c[2] as usize])];
                    while j != u32::MAX {
                        if (j as usize) > i {
                            let q = &x[j as usize];
                            let d2 = (q[0] - p[0]) * (q[0] - p[0])
                                + (q[1] - p[1]) * (q[1] - p[1])
                                + (q[2] - p[2]) * (q[2] - p[2]);
                            if d2 < range2 {
                                let at = partners
                                    .iter()
                                    .position(|&k| k > j)
                                    .unwrap_or(partners.len());
                                partners.insert(at, j).map_err(|_| crowded)?;
                            }
                        }
                        j = next[j as usize];
                    }
                }
            }
        }
        let r_xy = crate::math::sqrt(p[0] * p[0] + p[1] * p[1]);
        let walls = [
            (p[2] < radius + wall_gap, FLOOR),
            (r_xy > grid.half_width - radius - wall_gap, DIE),
        ];
        let js = partners
            .iter()
            .copied()
            .chain(walls.iter().filter(|w| w.0).map(|w| w.1));
        for j in js {
            // Carry the history of (i, j) over from the sorted old list.
            while o < old.len() && (old[o].i, old[o].j) < (i as u32, j) {
                o += 1;
            }
            let xi = if o < old.len() && (old[o].i, old[o].j) == (i as u32, j) {
                old[o].xi
            } else {
                [0.0; 3]
            };
            *out.get_mut(count).ok_or(overflow)? = Pair { i: i as u32, j, xi };
            count += 1;
        }
    }
    Ok(count)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec;
    use std::vec::Vec;

    const NO_PAIR: Pair = Pair {
        i: 0,
        j: 0,
        xi: [0.0; 3],
    };

    /// Spheres crowded at one point give one sphere more partners than the
    /// search holds: an overflow marked per sphere (a larger pair buffer
    /// does not help), where a short pair buffer alone is not.
    #[test]
    fn a_crowded_sphere_is_told_from_a_short_buffer() {
        let (radius, range) = (0.5e-3, 1.2e-3);
        let grid = Grid::new(5e-3, 5e-3, range);
        let (mut head, mut next) = (vec![0; grid.cells()], vec![0; 80]);
        let mut scratch = GridScratch {
            head: &mut head,
            next: &mut next,
        };
        let crowded: Vec<[Real; 3]> = (0..80).map(|k| [1e-6 * k as Real, 0.0, 2e-3]).collect();
        let mut out = vec![NO_PAIR; 100_000];
        let e = build_pairs(&grid, &crowded, radius, range, &mut scratch, &[], &mut out);
        assert_eq!(
            e,
            Err(PairOverflow {
                capacity: MAX_PARTNERS,
                per_sphere: true
            })
        );
        let apart: Vec<[Real; 3]> = (0..10)
            .map(|k| [1e-3 * (k % 3) as Real, 1e-3 * (k / 3) as Real, 2e-3])
            .collect();
        let mut short = vec![NO_PAIR; 2];
        let e = build_pairs(&grid, &apart, radius, range, &mut scratch, &[], &mut short);
        assert_eq!(
            e,
            Err(PairOverflow {
                capacity: 2,
                per_sphere: false
            })
        );
    }
}
