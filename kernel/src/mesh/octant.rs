//! The positive octant (x, y, z ≥ 0) of a mirror-symmetric mesh, for scenes
//! with three symmetry planes (a granule between platens): 1/8 of the work.
//!
//! Nodes keep their relative order, so the outer surface nodes stay last.
//! Nodes on a plane X_a = 0 must then have their a-velocity held at zero.

use crate::Real;
use crate::mesh::sphere::{MeshBuffers, MeshError, MeshSize};

/// A mesh borrowed from caller buffers (see [`MeshBuffers`] for layouts).
#[derive(Clone, Copy, Debug)]
pub struct MeshView<'a> {
    /// Reference node positions, m.
    pub positions: &'a [[Real; 3]],
    /// Hex connectivity.
    pub hexes: &'a [[u32; 8]],
    /// Outer surface quads.
    pub quads: &'a [[u32; 4]],
    /// Number of outer surface nodes (the last ones).
    pub surface_nodes: usize,
}

impl MeshView<'_> {
    /// [`MeshError::NodeOutOfRange`] if a hex or quad names a node beyond
    /// `positions`, or `surface_nodes` exceeds the node count;
    /// [`MeshError::NotSurfaceNode`] if a quad names a node before the last
    /// `surface_nodes` (per-node surface tables are indexed from the first
    /// surface node: [`extract_octant`] overflowed on one). What every
    /// routine that indexes positions by these ids checks first.
    pub fn check(&self) -> Result<(), MeshError> {
        let nodes = self.positions.len();
        if self.surface_nodes > nodes {
            return Err(MeshError::NodeOutOfRange {
                buffer: "surface_nodes",
                index: 0,
                id: self.surface_nodes,
                nodes,
            });
        }
        let bad = |buffer, ids: &mut dyn Iterator<Item = &[u32]>| {
            ids.enumerate().find_map(|(index, item)| {
                item.iter()
                    .find(|&&id| id as usize >= nodes)
                    .map(|&id| MeshError::NodeOutOfRange {
                        buffer,
                        index,
                        id: id as usize,
                        nodes,
                    })
            })
        };
        if let Some(e) = bad("hexes", &mut self.hexes.iter().map(|h| &h[..]))
            .or_else(|| bad("quads", &mut self.quads.iter().map(|q| &q[..])))
        {
            return Err(e);
        }
        let first_surface = nodes - self.surface_nodes;
        self.quads
            .iter()
            .enumerate()
            .find_map(|(quad, q)| {
                q.iter()
                    .find(|&&id| (id as usize) < first_surface)
                    .map(|&id| MeshError::NotSurfaceNode {
                        quad,
                        id: id as usize,
                        first_surface,
                    })
            })
            .map_or(Ok(()), Err)
    }
}

fn in_octant(x: &[Real; 3]) -> bool {
    x.iter().all(|&c| c >= 0.0)
}

fn all_in(view: &MeshView<'_>, ids: &[u32]) -> bool {
    ids.iter().all(|&i| in_octant(&view.positions[i as usize]))
}

/// Buffer sizes of the octant of `full`; `scratch` is `full`'s node count.
/// Errors: `full`'s ids out of range ([`MeshView::check`]).
pub fn octant_size(full: &MeshView<'_>) -> Result<MeshSize, MeshError> {
    full.check()?;
    let first_surface = full.positions.len() - full.surface_nodes;
    let nodes = full.positions.iter().filter(|x| in_octant(x)).count();
    let surface_nodes = full.positions[first_surface..]
        .iter()
        .filter(|x| in_octant(x))
        .count();
    Ok(MeshSize {
        nodes,
        hexes: full.hexes.iter().filter(|h| all_in(full, &h[..])).count(),
        quads: full.quads.iter().filter(|q| all_in(full, &q[..])).count(),
        surface_nodes,
        scratch: full.positions.len(),
    })
}

/// Writes the octant of `full` into `out` (sized by [`octant_size`]).
pub fn extract_octant(
    full: &MeshView<'_>,
    out: &mut MeshBuffers<'_>,
) -> Result<MeshSize, MeshError> {
    let size = octant_size(full)?;
    for (buffer, got, expected) in [
        ("positions", out.positions.len(), size.nodes),
        ("hexes", out.hexes.len(), size.hexes),
        ("quads", out.quads.len(), size.quads),
        ("node_quads", out.node_quads.len(), size.surface_nodes),
        ("scratch", out.scratch.len(), size.scratch),
    ] {
        if got != expected {
            return Err(MeshError::BufferLength {
                buffer,
                expected,
                got,
            });
        }
    }
    let mut next = 0u32;
    for (i, x) in full.positions.iter().enumerate() {
        out.scratch[i] = if in_octant(x) {
            out.positions[next as usize] = *x;
            next += 1;
            next - 1
        } else {
            u32::MAX
        };
    }
    let map = |id: u32| out.scratch[id as usize];
    for (e, h) in full
        .hexes
        .iter()
        .filter(|h| all_in(full, &h[..]))
        .enumerate()
    {
        out.hexes[e] = core::array::from_fn(|i| map(h[i]));
    }
    let first_surface = (size.nodes - size.surface_nodes) as u32;
    out.node_quads.fill([u32::MAX; 4]);
    for (f, q) in full
        .quads
        .iter()
        .filter(|q| all_in(full, &q[..]))
        .enumerate()
    {
        let ids: [u32; 4] = core::array::from_fn(|i| map(q[i]));
        out.quads[f] = ids;
        for id in ids {
            let slots = &mut out.node_quads[(id - first_surface) as usize];
            if let Some(slot) = slots.iter_mut().find(|s| **s == u32::MAX) {
                *slot = f as u32;
            }
        }
    }
    Ok(size)
}
