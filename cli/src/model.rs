//! Owned storage for the kernel's caller-buffer APIs: a granule reference
//! mesh (full sphere or octant) with its shared element data.

use anyhow::{Context as _, bail};
use granbed_kernel::Real;
use granbed_kernel::contact::face_lists::face_diagonal;
use granbed_kernel::dem::neighbors::Pair;
use granbed_kernel::dem::pour::{PourBuffers, PourParams};
use granbed_kernel::element::batch::{ElementBatch, batch_count, regroup};
use granbed_kernel::element::reference::HexReference;
use granbed_kernel::granule::dynamics::GranuleBuffers;
use granbed_kernel::granule::quality::reference_gauss_dets;
use granbed_kernel::granule::timestep::PowerIterationBuffers;
use granbed_kernel::mesh::octant::{MeshView, extract_octant, octant_size};
use granbed_kernel::mesh::reference::{ReferenceMesh, compute_element_data};
use granbed_kernel::mesh::sphere::{MeshBuffers, MeshSize, SphereMeshParams, generate};
use granbed_kernel::scene::platens::PlatenBuffers;

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

impl OwnedReference {
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

    /// Generates the sphere of `radius` (m) at `level`, the positive octant
    /// of it when `octant`, and computes the element data.
    pub fn sphere(radius: Real, level: MeshLevel, octant: bool) -> anyhow::Result<Self> {
        let params = SphereMeshParams::new(radius, level.n, level.m);
        let size = params
            .size()
            .with_context(|| format!("mesh level {level}"))?;
        let mut store = MeshStore::new(size);
        generate(&params, &mut store.buffers())
            .with_context(|| format!("generating the {level} sphere mesh"))?;
        let mut surface_nodes = size.surface_nodes;
        if octant {
            let full = store.view(surface_nodes);
            let osize = octant_size(&full);
            let mut part = MeshStore::new(osize);
            extract_octant(&full, &mut part.buffers())?;
            (store, surface_nodes) = (part, osize.surface_nodes);
        }
        let Some(first) = store
            .hexes
            .first()
            .map(|hex| core::array::from_fn(|i| store.positions[hex[i] as usize]))
        else {
            bail!("mesh level {level} has no elements");
        };
        let placeholder = granbed_kernel::element::reference::hex_reference(&first)
            .context("first element is inverted")?;
        let mut elements = vec![placeholder; store.hexes.len()];
        let mut node_volume = vec![0.0; store.positions.len()];
        compute_element_data(&store.view(surface_nodes), &mut elements, &mut node_volume)?;
        Ok(Self {
            positions: store.positions,
            hexes: store.hexes,
            quads: store.quads,
            node_quads: store.node_quads,
            surface_nodes,
            batches: regrouped(&elements),
            elements,
            node_volume,
            gauss_dets: Vec::new(),
        }
        .with_gauss_dets())
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

    /// Generates the hex cube of side `side` (m) with `n` divisions per edge,
    /// centred at the origin, and computes the element data.
    pub fn cube(side: Real, n: u32) -> anyhow::Result<Self> {
        let size = granbed_kernel::mesh::cube::cube_size(n)
            .with_context(|| format!("cube with {n} divisions"))?;
        let mut store = MeshStore::new(size);
        granbed_kernel::mesh::cube::generate_cube(side, n, &mut store.buffers())
            .with_context(|| format!("generating the {n}x{n}x{n} cube of side {side} m"))?;
        let Some(first) = store
            .hexes
            .first()
            .map(|hex| core::array::from_fn(|i| store.positions[hex[i] as usize]))
        else {
            bail!("the cube has no elements");
        };
        let placeholder = granbed_kernel::element::reference::hex_reference(&first)
            .context("first element is inverted")?;
        let mut elements = vec![placeholder; store.hexes.len()];
        let mut node_volume = vec![0.0; store.positions.len()];
        compute_element_data(
            &store.view(size.surface_nodes),
            &mut elements,
            &mut node_volume,
        )?;
        Ok(Self {
            positions: store.positions,
            hexes: store.hexes,
            quads: store.quads,
            node_quads: store.node_quads,
            surface_nodes: size.surface_nodes,
            batches: regrouped(&elements),
            elements,
            node_volume,
            gauss_dets: Vec::new(),
        }
        .with_gauss_dets())
    }

    /// `self` with its [`Self::gauss_dets`] taken.
    fn with_gauss_dets(mut self) -> Self {
        let mut dets = vec![[0.0; 8]; self.hexes.len()];
        reference_gauss_dets(&self.view(), &mut dets).expect("one per hex");
        self.gauss_dets = dets;
        self
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

/// Owned per-granule state for the kernel's [`GranuleBuffers`]: node
/// buffers for every node of the mesh and `points` C_p⁻¹ per element.
#[derive(Clone, Debug)]
pub struct GranuleStore {
    /// Positions, m.
    pub x: Vec<[Real; 3]>,
    /// Velocities, m/s.
    pub v: Vec<[Real; 3]>,
    /// Scratch: velocity before contact v*, m/s.
    pub v_star: Vec<[Real; 3]>,
    /// Predicted positions x̃, m.
    pub x_pred: Vec<[Real; 3]>,
    /// Internal + hourglass forces, N.
    pub f_int: Vec<[Real; 3]>,
    /// Contact forces of the step, N.
    pub f_c: Vec<[Real; 3]>,
    /// Damping forces, N.
    pub f_d: Vec<[Real; 3]>,
    /// Lumped masses, kg.
    pub mass: Vec<Real>,
    /// The masses the kinematic contact sees, kg: `mass`, or under selective
    /// mass scaling the effective nodal masses of
    /// [`granbed_kernel::granule::damping::selective_contact_masses`]
    /// (set by the owner of the contact phase; the assembly sets them on
    /// the surface nodes only, which are all that contact touches: the
    /// interior entries are not kept up to date and nothing reads them).
    pub contact_mass: Vec<Real>,
    /// Per node, bit a = velocity component a held at zero.
    pub fixed: Vec<u8>,
    /// C_p⁻¹ per integration point.
    pub cp_inv: Vec<[Real; 6]>,
}

impl GranuleStore {
    /// Zeroed buffers for `mesh` with `points` integration points per element
    /// (the kernel's scene or [`GranuleBuffers::reset`] initialises them).
    pub fn new(mesh: &OwnedReference, points: usize) -> Self {
        let n = mesh.positions.len();
        Self {
            x: vec![[0.0; 3]; n],
            v: vec![[0.0; 3]; n],
            v_star: vec![[0.0; 3]; n],
            x_pred: vec![[0.0; 3]; n],
            f_int: vec![[0.0; 3]; n],
            f_c: vec![[0.0; 3]; n],
            f_d: vec![[0.0; 3]; n],
            mass: vec![0.0; n],
            contact_mass: vec![0.0; n],
            fixed: vec![0; n],
            cp_inv: vec![[0.0; 6]; mesh.hexes.len() * points],
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> GranuleBuffers<'_> {
        GranuleBuffers {
            x: &mut self.x,
            v: &mut self.v,
            v_star: &mut self.v_star,
            x_pred: &mut self.x_pred,
            f_int: &mut self.f_int,
            f_c: &mut self.f_c,
            f_d: &mut self.f_d,
            mass: &mut self.mass,
            fixed: &mut self.fixed,
            cp_inv: &mut self.cp_inv,
        }
    }
}

/// Owned scratch for the kernel's power iteration (the global time-step
/// estimate) of one granule.
#[derive(Clone, Debug)]
pub struct PowerStore {
    mode: Vec<[Real; 3]>,
    x_pert: Vec<[Real; 3]>,
    f_plus: Vec<[Real; 3]>,
    f_minus: Vec<[Real; 3]>,
    cp_scratch: Vec<[Real; 6]>,
}

impl PowerStore {
    /// Buffers for `mesh` with `points` integration points per element.
    pub fn new(mesh: &OwnedReference, points: usize) -> Self {
        let n = mesh.positions.len();
        Self {
            mode: vec![[0.0; 3]; n],
            x_pert: vec![[0.0; 3]; n],
            f_plus: vec![[0.0; 3]; n],
            f_minus: vec![[0.0; 3]; n],
            cp_scratch: vec![[0.0; 6]; mesh.hexes.len() * points],
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> PowerIterationBuffers<'_> {
        PowerIterationBuffers {
            mode: &mut self.mode,
            x_pert: &mut self.x_pert,
            f_plus: &mut self.f_plus,
            f_minus: &mut self.f_minus,
            cp_scratch: &mut self.cp_scratch,
        }
    }
}

/// Owned state of the single-granule platen experiment.
#[derive(Clone, Debug)]
pub struct PlatenStore {
    /// The granule.
    pub granule: GranuleStore,
    /// Time-step scratch.
    pub power: PowerStore,
}

impl PlatenStore {
    /// Buffers for `mesh` with `points` integration points per element.
    pub fn new(mesh: &OwnedReference, points: usize) -> Self {
        Self {
            granule: GranuleStore::new(mesh, points),
            power: PowerStore::new(mesh, points),
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> PlatenBuffers<'_> {
        PlatenBuffers {
            granule: self.granule.buffers(),
            power: self.power.buffers(),
        }
    }
}

/// Owned buffers of the discrete-element pour ([`PourBuffers`]).
#[derive(Clone, Debug)]
pub struct PourStore {
    /// Centres, m.
    pub x: Vec<[Real; 3]>,
    /// Velocities, m/s.
    pub v: Vec<[Real; 3]>,
    omega: Vec<[Real; 3]>,
    f: Vec<[Real; 3]>,
    torque: Vec<[Real; 3]>,
    x_built: Vec<[Real; 3]>,
    pairs: Vec<Pair>,
    pairs_old: Vec<Pair>,
    head: Vec<u32>,
    next: Vec<u32>,
}

impl PourStore {
    /// Buffers for `params`, with room for 12 candidate pairs per sphere.
    pub fn new(params: &PourParams) -> Self {
        let n = params.granules;
        let z = [0.0; 3];
        let empty = Pair { i: 0, j: 0, xi: z };
        Self {
            x: vec![z; n],
            v: vec![z; n],
            omega: vec![z; n],
            f: vec![z; n],
            torque: vec![z; n],
            x_built: vec![z; n],
            pairs: vec![empty; 12 * n],
            pairs_old: vec![empty; 12 * n],
            head: vec![0; params.grid().cells()],
            next: vec![0; n],
        }
    }

    /// The kernel's borrowed view.
    pub fn buffers(&mut self) -> PourBuffers<'_> {
        PourBuffers {
            x: &mut self.x,
            v: &mut self.v,
            omega: &mut self.omega,
            f: &mut self.f,
            torque: &mut self.torque,
            x_built: &mut self.x_built,
            pairs: &mut self.pairs,
            pairs_old: &mut self.pairs_old,
            head: &mut self.head,
            next: &mut self.next,
        }
    }
}
