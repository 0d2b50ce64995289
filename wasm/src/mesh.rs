//! The granule's reference mesh and the run buffers, owned here for the
//! program's lifetime.
//!
//! The kernel's [`PlatenScene`](granbed_kernel::scene::platens::PlatenScene)
//! borrows its mesh and buffers; a handle that JavaScript keeps between
//! calls cannot hold a borrow of its own fields, so the storage is given
//! `'static` lifetime once and reused: meshes are cached per (diameter,
//! level) and run buffers go back to a pool when a run is dropped (see
//! [`crate::experiment::Experiment`]). Memory therefore grows only with the
//! number of distinct diameters and of runs alive at once, not with the
//! number of runs.

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;
use core::cell::RefCell;

use granbed_kernel::Real;
use granbed_kernel::element::batch::{ElementBatch, batch_count, regroup};
use granbed_kernel::element::reference::{HexReference, hex_reference};
use granbed_kernel::granule::dynamics::GranuleBuffers;
use granbed_kernel::granule::timestep::PowerIterationBuffers;
use granbed_kernel::mesh::octant::{MeshView, extract_octant, octant_size};
use granbed_kernel::mesh::reference::{ReferenceMesh, compute_element_data};
use granbed_kernel::mesh::sphere::{MeshBuffers, MeshSize, SphereMeshParams, generate};
use granbed_kernel::scene::platens::PlatenBuffers;

/// The positive octant of the cubed-sphere mesh with its element data
/// (the same construction as the CLI's `OwnedReference::sphere(r, level,
/// true)`).
#[derive(Debug)]
pub struct OctantMesh {
    /// Reference node positions, m.
    pub positions: Vec<[Real; 3]>,
    /// Hex connectivity.
    pub hexes: Vec<[u32; 8]>,
    /// Outer surface quads.
    pub quads: Vec<[u32; 4]>,
    /// Quads of each surface node.
    pub node_quads: Vec<[u32; 4]>,
    /// Outer surface nodes (the last ones).
    pub surface_nodes: usize,
    /// Per-element reference data.
    pub elements: Vec<HexReference>,
    /// `elements` regrouped for the batched element (`batch::regroup`).
    pub batches: Vec<ElementBatch>,
    /// Lumped nodal volumes, m³.
    pub node_volume: Vec<Real>,
}

struct MeshStore {
    positions: Vec<[Real; 3]>,
    hexes: Vec<[u32; 8]>,
    quads: Vec<[u32; 4]>,
    node_quads: Vec<[u32; 4]>,
    scratch: Vec<u32>,
}

impl MeshStore {
    fn new(size: MeshSize) -> Self {
        Self {
            positions: vec![[0.0; 3]; size.nodes],
            hexes: vec![[0; 8]; size.hexes],
            quads: vec![[0; 4]; size.quads],
            node_quads: vec![[0; 4]; size.surface_nodes],
            scratch: vec![0; size.scratch],
        }
    }

    fn buffers(&mut self) -> MeshBuffers<'_> {
        MeshBuffers {
            positions: &mut self.positions,
            hexes: &mut self.hexes,
            quads: &mut self.quads,
            node_quads: &mut self.node_quads,
            scratch: &mut self.scratch,
        }
    }

    fn view(&self, surface_nodes: usize) -> MeshView<'_> {
        MeshView {
            positions: &self.positions,
            hexes: &self.hexes,
            quads: &self.quads,
            surface_nodes,
        }
    }
}

impl OctantMesh {
    /// The octant of the sphere of `radius` (m) with `n` core divisions and
    /// `m` shell layers; `None` if the kernel rejects the level or radius.
    pub fn generate(radius: Real, n: u32, m: u32) -> Option<Self> {
        let params = SphereMeshParams::new(radius, n, m);
        let size = params.size().ok()?;
        let mut full = MeshStore::new(size);
        generate(&params, &mut full.buffers()).ok()?;
        let full_view = full.view(size.surface_nodes);
        let osize = octant_size(&full_view);
        let mut part = MeshStore::new(osize);
        extract_octant(&full_view, &mut part.buffers()).ok()?;
        let first = part.hexes.first()?;
        let corners = core::array::from_fn(|i| {
            part.positions
                .get(first[i] as usize)
                .copied()
                .unwrap_or_default()
        });
        let placeholder = hex_reference(&corners)?;
        let mut elements = vec![placeholder; part.hexes.len()];
        let mut node_volume = vec![0.0; part.positions.len()];
        compute_element_data(
            &part.view(osize.surface_nodes),
            &mut elements,
            &mut node_volume,
        )
        .ok()?;
        Some(Self {
            positions: part.positions,
            hexes: part.hexes,
            quads: part.quads,
            node_quads: part.node_quads,
            surface_nodes: osize.surface_nodes,
            batches: {
                let mut batches = vec![ElementBatch::ZERO; batch_count(elements.len())];
                regroup(&elements, &mut batches).ok()?;
                batches
            },
            elements,
            node_volume,
        })
    }

    /// The kernel's borrowed view.
    pub fn view(&self) -> ReferenceMesh<'_> {
        ReferenceMesh {
            mesh: MeshView {
                positions: &self.positions,
                hexes: &self.hexes,
                quads: &self.quads,
                surface_nodes: self.surface_nodes,
            },
            node_quads: &self.node_quads,
            elements: &self.elements,
            batches: &self.batches,
            node_volume: &self.node_volume,
        }
    }
}

type MeshKey = (u64, u32, u32);

std::thread_local! {
    static MESHES: RefCell<Vec<(MeshKey, &'static OctantMesh)>> = const { RefCell::new(Vec::new()) };
    static POOL: RefCell<Vec<PlatenBuffers<'static>>> = const { RefCell::new(Vec::new()) };
}

/// The cached octant mesh of `radius` at level `n`x`m`, generated on first
/// use; `None` if the kernel rejects it.
pub fn octant_mesh(radius: Real, n: u32, m: u32) -> Option<&'static OctantMesh> {
    let key = (radius.to_bits(), n, m);
    if let Some(mesh) = MESHES.with_borrow(|c| c.iter().find(|(k, _)| *k == key).map(|(_, m)| *m)) {
        return Some(mesh);
    }
    let mesh: &'static OctantMesh = Box::leak(Box::new(OctantMesh::generate(radius, n, m)?));
    MESHES.with_borrow_mut(|c| c.push((key, mesh)));
    Some(mesh)
}

/// Run buffers for `nodes` nodes and `states` C_p⁻¹ entries: a pooled set of
/// that size, or a new one (the scene initialises them either way).
pub fn take_buffers(nodes: usize, states: usize) -> PlatenBuffers<'static> {
    let pooled = POOL.with_borrow_mut(|pool| {
        let i = pool
            .iter()
            .position(|b| b.granule.x.len() == nodes && b.granule.cp_inv.len() == states)?;
        Some(pool.swap_remove(i))
    });
    pooled.unwrap_or_else(|| new_buffers(nodes, states))
}

/// Returns `buffers` to the pool for the next run.
pub fn give_back(buffers: PlatenBuffers<'static>) {
    POOL.with_borrow_mut(|pool| pool.push(buffers));
}

fn leak<T: Clone>(len: usize, value: T) -> &'static mut [T] {
    vec![value; len].leak()
}

fn new_buffers(nodes: usize, states: usize) -> PlatenBuffers<'static> {
    let z3 = [0.0; 3];
    PlatenBuffers {
        granule: GranuleBuffers {
            x: leak(nodes, z3),
            v: leak(nodes, z3),
            v_star: leak(nodes, z3),
            x_pred: leak(nodes, z3),
            f_int: leak(nodes, z3),
            f_c: leak(nodes, z3),
            f_d: leak(nodes, z3),
            mass: leak(nodes, 0.0),
            fixed: leak(nodes, 0),
            cp_inv: leak(states, [0.0; 6]),
        },
        power: PowerIterationBuffers {
            mode: leak(nodes, z3),
            x_pert: leak(nodes, z3),
            f_plus: leak(nodes, z3),
            f_minus: leak(nodes, z3),
            cp_scratch: leak(states, [0.0; 6]),
        },
    }
}
