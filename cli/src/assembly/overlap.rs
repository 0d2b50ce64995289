//! The overlap of the granules measured by geometry alone
//! ([`granbed_kernel::analysis::overlap`]): the check of what the contact
//! detection reports ([`Assembly::penetration`]), which shares none of its
//! choices (normals, windows, nearest faces).

use granbed_kernel::Real;
use granbed_kernel::analysis::overlap::depth_inside;
use granbed_kernel::contact::surface::Aabb;
use rayon::prelude::*;

use super::Assembly;

/// The deepest surface node of one granule inside another.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overlap {
    /// Its depth: the distance to the other granule's surface, m (0 if no
    /// node is inside another granule; NaN if a surface node's position is
    /// not finite, which it then names, with `inside` its own granule).
    pub depth_m: Real,
    /// The granule whose node it is.
    pub granule: usize,
    /// The node (index into the granule's nodes).
    pub node: usize,
    /// The granule it is inside.
    pub inside: usize,
}

impl Overlap {
    /// The deeper of two (the first on a tie; a NaN wins and, once held,
    /// stays, so that a non-finite state is reported, not hidden).
    pub fn deeper(self, other: Overlap) -> Overlap {
        if other.depth_m > self.depth_m || (other.depth_m.is_nan() && !self.depth_m.is_nan()) {
            other
        } else {
            self
        }
    }
}

impl Assembly<'_> {
    /// The deepest surface node of any granule inside another at the
    /// current positions x_n: every surface node inside another granule's
    /// surface box is tested with that granule's closed surface (winding
    /// number, then the distance to it). Granule pairs in parallel, the
    /// deepest kept in pair order, so the result is the same for any
    /// thread count. Costly (one `atan2` per surface triangle and node
    /// tested: about a second for 30 coarse granules pressed to 60 %):
    /// for checks at a few strains, not every step.
    pub fn hidden_overlap(&self) -> Overlap {
        let surface = self.mesh.surface_range();
        let quads = &self.mesh.quads;
        // A surface node that is not finite has no depth, and its
        // granule's box would leave it out: reported as it is.
        for (g, granule) in self.granules.iter().enumerate() {
            let bad = granule.x[surface.clone()]
                .iter()
                .position(|p| !p.iter().all(|c| c.is_finite()));
            if let Some(i) = bad {
                return Overlap {
                    depth_m: Real::NAN,
                    granule: g,
                    node: surface.start + i,
                    inside: g,
                };
            }
        }
        let boxes: Vec<Aabb> = self
            .granules
            .iter()
            .map(|g| Aabb::of_surface(&g.x, surface.start))
            .collect();
        let pairs: Vec<(usize, usize)> = (0..boxes.len())
            .flat_map(|a| (a + 1..boxes.len()).map(move |b| (a, b)))
            .filter(|&(a, b)| boxes[a].overlaps(&boxes[b]))
            .collect();
        pairs
            .par_iter()
            .map(|&(a, b)| {
                let mut deepest = Overlap::default();
                for (g, other) in [(a, b), (b, a)] {
                    let (x, y) = (&self.granules[g].x, &self.granules[other].x);
                    for node in surface.clone() {
                        let p = &x[node];
                        if !boxes[other].contains(p) {
                            continue;
                        }
                        // A mesh whose quads name nodes it does not have
                        // cannot be measured: NaN.
                        let depth_m = depth_inside(p, y, quads).unwrap_or(Real::NAN);
                        deepest = deepest.deeper(Overlap {
                            depth_m,
                            granule: g,
                            node,
                            inside: other,
                        });
                    }
                }
                deepest
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold(Overlap::default(), Overlap::deeper)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{AssemblyParams, Placement};
    use crate::model::{MeshLevel, OwnedReference};
    use granbed_kernel::granule::forces::{ElementKind, ElementSettings};
    use granbed_kernel::material::GranuleType;

    /// Two coarse 1 mm granules on the x axis whose centres are 1 mm − δ
    /// apart: the poles facing each other are mesh nodes, each δ inside the
    /// other granule. The measure by geometry finds that depth (less the
    /// tilt of the facets around the pole: 0.963 δ on the coarse mesh), as
    /// the contact detection does to 10⁻⁴ δ, and nothing when the granules
    /// are δ apart (on a diagonal, so that their boxes overlap and their
    /// nodes are tested). A NaN node is reported as such.
    #[test]
    fn two_granules_pressed_together_overlap_by_what_they_were_pushed() {
        let mesh = OwnedReference::sphere(0.5e-3, MeshLevel::new(4, 1), false).unwrap();
        let material = GranuleType::B2.params().validate().unwrap();
        let elements = ElementSettings {
            kind: ElementKind::OnePoint,
            update: Default::default(),
            hourglass_kappa: 0.05,
        };
        let params = AssemblyParams::standard(material, elements);
        let delta = 1.0e-5;
        let (close, apart) = (1.0e-3 - delta, 1.0e-3 + delta);
        // Apart along a diagonal, whose boxes overlap, so that the
        // granules' nodes are tested against each other.
        let diagonal = apart / Real::sqrt(2.0);
        for (centre, want) in [([close, 0.0, 0.0], delta), ([diagonal, diagonal, 0.0], 0.0)] {
            let placements = [Placement::at([0.0; 3]), Placement::at(centre)];
            let asm = Assembly::new(params, &mesh, &placements, Vec::new()).unwrap();
            let found = asm.hidden_overlap();
            let detected = -asm.penetration().unwrap();
            if want == 0.0 {
                assert_eq!(found, Overlap::default());
                assert_eq!(detected, 0.0);
                continue;
            }
            assert!(
                found.depth_m <= want * (1.0 + 1e-9) && found.depth_m > 0.95 * want,
                "{found:?}"
            );
            // Measured: 9.62637e-6 against 9.62660e-6 m.
            assert!(
                (found.depth_m - detected).abs() < 1e-4 * want,
                "{found:?} vs {detected}"
            );
            assert_eq!(found.inside, 1 - found.granule);
            let x = asm.granules()[found.granule].x[found.node];
            assert!(x[1].abs() < 1e-12 && x[2].abs() < 1e-12, "the pole: {x:?}");
        }
        let placements = [Placement::at([0.0; 3]), Placement::at([3e-3, 0.0, 0.0])];
        let mut asm = Assembly::new(params, &mesh, &placements, Vec::new()).unwrap();
        let last = mesh.positions.len() - 1;
        asm.granules_mut()[1].x[last][0] = Real::NAN;
        let found = asm.hidden_overlap();
        assert!(found.depth_m.is_nan());
        assert_eq!((found.granule, found.node), (1, last));
    }
}
