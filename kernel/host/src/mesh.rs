//! A granule's reference mesh and its element data in owned buffers.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use granbed_kernel::Real;
use granbed_kernel::contact::face_lists::face_diagonal;
use granbed_kernel::element::batch::{ElementBatch, batch_count, regroup};
use granbed_kernel::element::reference::HexReference;
use granbed_kernel::granule::quality::reference_gauss_dets;
use granbed_kernel::mesh::cube::{cube_size, generate_cube};
use granbed_kernel::mesh::octant::{MeshView, extract_octant, octant_size};
use granbed_kernel::mesh::reference::{ReferenceMesh, compute_element_data};
use granbed_kernel::mesh::sphere::{MeshBuffers, MeshError, MeshSize, SphereMeshParams, generate};

/// A mesh resolution "NxM": n core divisions, m shell layers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshLevel {
    /// Core divisions n (even).
    pub n: u32,
    /// Shell layers m.
    pub m: u32,
}

impl MeshLevel {
    /// The standard 1280-hex level 8x2.
    pub const STANDARD: MeshLevel = MeshLevel { n: 8, m: 2 };

    /// The level n×m (validated when the mesh is generated).
    pub const fn new(n: u32, m: u32) -> Self {
        Self { n, m }
    }
}

impl core::str::FromStr for MeshLevel {
    type Err = String;

    /// Parses `NxM`, e.g. `8x2` (1280 hexes), `4x1` (160), `16x4`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || {
            format!(
                "`{s}` is not a mesh level NxM (e.g. 4x1, 8x2, 16x4; n even in 2..=64, m in 1..=32)"
            )
        };
        let (n, m) = s.split_once(['x', 'X']).ok_or_else(err)?;
        let level = MeshLevel {
            n: n.trim().parse().map_err(|_| err())?,
            m: m.trim().parse().map_err(|_| err())?,
        };
        SphereMeshParams::new(0.5e-3, level.n, level.m)
            .size()
            .map_err(|_| err())?;
        Ok(level)
    }
}

impl core::fmt::Display for MeshLevel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}x{}", self.n, self.m)
    }
}

/// A reference mesh and its element data in owned buffers.
#[derive(Clone, Debug)]
pub struct OwnedReference {
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
    /// det J at each element's 2×2×2 Gauss points on the reference mesh,
    /// `[element][point]`, m³ (`quality::reference_gauss_dets`): what the
    /// worst-element check of every granule divides by.
    pub gauss_dets: Vec<[Real; 8]>,
}

/// `elements` regrouped for the batched one-point element.
pub fn regrouped(elements: &[HexReference]) -> Vec<ElementBatch> {
    let mut batches = vec![ElementBatch::ZERO; batch_count(elements.len())];
    regroup(elements, &mut batches).expect("sized by batch_count");
    batches
}

/// Owned mesh buffers of one size, lent to the kernel as [`MeshBuffers`].
struct MeshStore {
    positions: Vec<[Real; 3]>,
    hexes: Vec<[u32; 8]>,
    quads: Vec<[u32; 4]>,
    node_quads: Vec<[u32; 4]>,
    scratch: Vec<u32>,
    surface_nodes: usize,
}

impl MeshStore {
    fn new(size: MeshSize) -> Self {
        Self {
            positions: vec![[0.0; 3]; size.nodes],
            hexes: vec![[0; 8]; size.hexes],
            quads: vec![[0; 4]; size.quads],
            node_quads: vec![[0; 4]; size.surface_nodes],
            scratch: vec![0; size.scratch],
            surface_nodes: size.surface_nodes,
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

    fn view(&self) -> MeshView<'_> {
        MeshView {
            positions: &self.positions,
            hexes: &self.hexes,
            quads: &self.quads,
            surface_nodes: self.surface_nodes,
        }
    }
}

/// Entries that [`compute_element_data`] writes over (every field of every
/// element).
const UNSET_REFERENCE: HexReference = HexReference {
    volume: 0.0,
    b0: [[0.0; 3]; 8],
    gamma0: [[0.0; 8]; 4],
    hourglass_geometry: 0.0,
    node_volume: [0.0; 8],
};

impl OwnedReference {
    /// Generates the sphere of `radius` (m) at `level`, the positive octant
    /// of it when `octant`, and computes the element data. Errors: the
    /// kernel's, for a level or radius out of range.
    pub fn sphere(radius: Real, level: MeshLevel, octant: bool) -> Result<Self, MeshError> {
        let params = SphereMeshParams::new(radius, level.n, level.m);
        let mut store = MeshStore::new(params.size()?);
        generate(&params, &mut store.buffers())?;
        if octant {
            let full = store.view();
            let mut part = MeshStore::new(octant_size(&full)?);
            extract_octant(&full, &mut part.buffers())?;
            store = part;
        }
        Self::with_element_data(store)
    }

    /// Generates the hex cube of side `side` (m) with `n` divisions per edge,
    /// centred at the origin, and computes the element data. Errors: the
    /// kernel's, for `n` or `side` out of range.
    pub fn cube(side: Real, n: u32) -> Result<Self, MeshError> {
        let mut store = MeshStore::new(cube_size(n)?);
        generate_cube(side, n, &mut store.buffers())?;
        Self::with_element_data(store)
    }

    /// The mesh of `store` with its element data, batches and reference
    /// Gauss-point determinants.
    fn with_element_data(store: MeshStore) -> Result<Self, MeshError> {
        let mut elements = vec![UNSET_REFERENCE; store.hexes.len()];
        let mut node_volume = vec![0.0; store.positions.len()];
        compute_element_data(&store.view(), &mut elements, &mut node_volume)?;
        let mut mesh = Self {
            batches: regrouped(&elements),
            positions: store.positions,
            hexes: store.hexes,
            quads: store.quads,
            node_quads: store.node_quads,
            surface_nodes: store.surface_nodes,
            elements,
            node_volume,
            gauss_dets: Vec::new(),
        };
        let mut dets = vec![[0.0; 8]; mesh.hexes.len()];
        reference_gauss_dets(&mesh.view(), &mut dets).expect("one per hex");
        mesh.gauss_dets = dets;
        Ok(mesh)
    }

    /// The outer surface nodes' indices (the last `surface_nodes` nodes):
    /// the only nodes contact forces act on.
    pub fn surface_range(&self) -> core::ops::Range<usize> {
        self.positions.len() - self.surface_nodes..self.positions.len()
    }

    /// Mean of the surface quads' larger diagonals on the reference
    /// positions, m (0 without quads).
    pub fn mean_face_diagonal(&self) -> Real {
        let sum: Real = self
            .quads
            .iter()
            .map(|q| face_diagonal(&q.map(|i| self.positions[i as usize])))
            .sum();
        sum / (self.quads.len().max(1) as Real)
    }

    /// The shortest edge of the surface quads, m: the element size that
    /// contact tolerances are stated against (penetration < 1 % of it).
    pub fn shortest_surface_edge(&self) -> Real {
        self.quads
            .iter()
            .flat_map(|q| (0..4).map(move |k| (q[k], q[(k + 1) % 4])))
            .map(|(a, b)| {
                let (p, q) = (self.positions[a as usize], self.positions[b as usize]);
                let d: [Real; 3] = core::array::from_fn(|i| p[i] - q[i]);
                granbed_kernel::math::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            })
            .fold(Real::INFINITY, Real::min)
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
