//! Element quality of a deformed granule beyond what the one-point element
//! sees: the one-point element samples F at the element centre only, so an
//! hourglass-distorted hex can fold at its Gauss points (a partly inverted
//! element) while its centre Jacobian stays healthy.

use crate::Real;
use crate::element::hex8;
use crate::mesh::reference::ReferenceMesh;
use crate::tensor::det_mat;

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

/// The smallest Gauss-point Jacobian ratio of the granule at positions `x`
/// (one per mesh node, m) against the reference mesh, with its element;
/// `None` for a mesh without elements. A NaN ratio wins (it is reported,
/// not skipped).
pub fn worst_element(mesh: &ReferenceMesh<'_>, x: &[[Real; 3]]) -> Option<WorstElement> {
    let reference = mesh.mesh.positions;
    let mut worst: Option<WorstElement> = None;
    for (e, hex) in mesh.mesh.hexes.iter().enumerate() {
        let now: hex8::HexCoords = core::array::from_fn(|i| x[hex[i] as usize]);
        let then: hex8::HexCoords = core::array::from_fn(|i| reference[hex[i] as usize]);
        for g in hex8::gauss_points() {
            let ratio = det_mat(&hex8::jacobian(&now, g)) / det_mat(&hex8::jacobian(&then, g));
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
