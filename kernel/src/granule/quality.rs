//! Element quality of a deformed granule beyond what the one-point element
//! sees: the one-point element samples F at the element centre only, so an
//! hourglass-distorted hex can fold at its Gauss points (a partly inverted
//! element) while its centre Jacobian stays healthy.

use crate::Real;
use crate::element::reference::gauss_determinants;
use crate::mesh::reference::ReferenceMesh;

/// The worst element of a granule: the smallest ratio det J_g(x)/det J_g(X)
/// over the 2×2×2 Gauss points of every element, and that element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorstElement {
    /// Smallest Gauss-point Jacobian ratio (≤ 0: the element is folded
    /// there; NaN if a position is not finite).
    pub ratio: Real,
    /// Its element (hex) index.
    pub element: usize,
}

/// det J_g at the Gauss points of the hex `hex` with node positions `x`. A
/// node id past `x` (positions shorter than the mesh, or a hex naming a
/// node it does not have) counts as a position that is not finite: NaN
/// determinants, which the ratios report, instead of an index panic.
#[inline]
fn gauss_dets(x: &[[Real; 3]], hex: &[u32; 8]) -> [Real; 8] {
    let node = |i: usize| x.get(hex[i] as usize).copied().unwrap_or([Real::NAN; 3]);
    gauss_determinants(&core::array::from_fn(node))
}

/// det J_g(X) of every element of `mesh` at its 2×2×2 Gauss points (in
/// [`crate::element::hex8::gauss_points`] order), `[element][point]`, m³: the denominators
/// of [`worst_element_against`], the same for every granule of the mesh.
/// `Err` holds the length `out` must have (one per hex).
pub fn reference_gauss_dets(mesh: &ReferenceMesh<'_>, out: &mut [[Real; 8]]) -> Result<(), usize> {
    let hexes = mesh.mesh.hexes;
    if out.len() != hexes.len() {
        return Err(hexes.len());
    }
    for (o, hex) in out.iter_mut().zip(hexes) {
        *o = gauss_dets(mesh.mesh.positions, hex);
    }
    Ok(())
}

/// The smallest Gauss-point Jacobian ratio of the granule at positions `x`
/// (one per mesh node, m) against the reference mesh, with its element;
/// `None` for a mesh without elements. A NaN ratio wins (it is reported,
/// not skipped): a position that is not finite, or a node `x` does not
/// have, gives one. [`worst_element_against`] with the reference determinants
/// taken on the way.
pub fn worst_element(mesh: &ReferenceMesh<'_>, x: &[[Real; 3]]) -> Option<WorstElement> {
    worst_element_against(mesh, &[], x)
}

/// [`worst_element`] with the reference determinants `reference` of
/// [`reference_gauss_dets`] (a driver checking many granules of one mesh
/// takes them once: they were two thirds of the work). If `reference` is not one
/// per hex (empty, say), or its first and last rows are not those of the
/// mesh's first and last elements (a cheap check against the table of
/// another mesh), they are taken on the way; the same bits either way.
pub fn worst_element_against(
    mesh: &ReferenceMesh<'_>,
    reference: &[[Real; 8]],
    x: &[[Real; 3]],
) -> Option<WorstElement> {
    let hexes = mesh.mesh.hexes;
    let row_matches = |e: usize| {
        let want = gauss_dets(mesh.mesh.positions, &hexes[e]);
        reference[e]
            .iter()
            .zip(&want)
            .all(|(r, w)| r.to_bits() == w.to_bits())
    };
    let cached = reference.len() == hexes.len()
        && (hexes.is_empty() || (row_matches(0) && row_matches(hexes.len() - 1)));
    let mut worst: Option<WorstElement> = None;
    for (e, hex) in hexes.iter().enumerate() {
        let now = gauss_dets(x, hex);
        let then = if cached {
            reference[e]
        } else {
            gauss_dets(mesh.mesh.positions, hex)
        };
        for (n, t) in now.iter().zip(&then) {
            let ratio = n / t;
            let worse = match worst {
                None => true,
                Some(w) => ratio.is_nan() && !w.ratio.is_nan() || ratio < w.ratio,
            };
            if worse {
                worst = Some(WorstElement { ratio, element: e });
            }
        }
    }
    worst
}
