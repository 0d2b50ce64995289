//! A granule's reference mesh with the element data shared by every granule
//! that uses it (physics.md §2.1): computed once per mesh level; a granule
//! then owns only its x, v, f and C_p⁻¹.

use crate::Real;
use crate::element::batch::ElementBatch;
use crate::element::reference::{HexReference, hex_reference};
use crate::mesh::octant::MeshView;
use crate::mesh::sphere::MeshError;

/// The reference mesh and its per-element data, borrowed from caller buffers.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceMesh<'a> {
    /// The mesh (reference positions X, connectivity, surface).
    pub mesh: MeshView<'a>,
    /// For each surface node s (node id = first surface node + s), its quads
    /// (`u32::MAX` marks unused slots).
    pub node_quads: &'a [[u32; 4]],
    /// Per-element reference data, one per hex.
    pub elements: &'a [HexReference],
    /// `elements` regrouped for the batched one-point element
    /// ([`crate::element::batch::regroup`], `batch_count(hexes)` long), or
    /// empty to have each batch gather its lanes (slower, the same bits).
    /// It must be regrouped from these `elements`: the element loop checks
    /// only its length and the volumes of its first and last batch (a
    /// full comparison would cost what regrouping saves), so the data of
    /// another mesh with equal volumes there, e.g. a rotated copy, would
    /// be used and give wrong forces.
    pub batches: &'a [ElementBatch],
    /// Lumped volume share of each node (Σ over its elements), m³; nodal
    /// mass = ρ0 × this.
    pub node_volume: &'a [Real],
}

impl ReferenceMesh<'_> {
    /// Index of the first outer surface node (0 for a mesh claiming more
    /// surface nodes than nodes, which [`MeshView::check`] refuses).
    ///
    /// [`MeshView::check`]: crate::mesh::octant::MeshView::check
    pub fn first_surface_node(&self) -> usize {
        self.mesh
            .positions
            .len()
            .saturating_sub(self.mesh.surface_nodes)
    }

    /// Total reference volume Σ V0, m³.
    pub fn volume(&self) -> Real {
        self.elements.iter().map(|e| e.volume).sum()
    }
}

/// Computes the element data (`elements`, one per hex) and the assembled
/// lumped nodal volumes (`node_volume`, one per node) of `mesh`, summing in
/// element order. Errors: a buffer length, an id out of range
/// ([`MeshView::check`]), an inverted element.
pub fn compute_element_data(
    mesh: &MeshView<'_>,
    elements: &mut [HexReference],
    node_volume: &mut [Real],
) -> Result<(), MeshError> {
    for (buffer, got, expected) in [
        ("elements", elements.len(), mesh.hexes.len()),
        ("node_volume", node_volume.len(), mesh.positions.len()),
    ] {
        if got != expected {
            return Err(MeshError::BufferLength {
                buffer,
                expected,
                got,
            });
        }
    }
    mesh.check()?;
    node_volume.fill(0.0);
    for (e, (hex, out)) in mesh.hexes.iter().zip(elements.iter_mut()).enumerate() {
        let x = core::array::from_fn(|i| mesh.positions[hex[i] as usize]);
        *out = hex_reference(&x).ok_or(MeshError::InvertedElement {
            element: e,
            corner: 0,
        })?;
        for (id, v) in hex.iter().zip(out.node_volume.iter()) {
            node_volume[*id as usize] += v;
        }
    }
    Ok(())
}
