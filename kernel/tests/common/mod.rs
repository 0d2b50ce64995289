//! Shared helpers of the kernel's test suites: one tolerance check, a seeded
//! generator, and independent (test-side) formulas of the yield surface.
#![allow(dead_code)]

use granbed_kernel::Real;
use granbed_kernel::material::{GranuleType, Material, MaterialParams};
use granbed_kernel::tensor::{Mat3, Voigt, deviator, norm, trace};

/// Asserts |actual − expected| ≤ abs + rel·|expected|, naming the quantity.
#[track_caller]
pub fn assert_close(what: &str, actual: Real, expected: Real, rel: Real, abs: Real) {
    let err = (actual - expected).abs();
    let tol = abs + rel * expected.abs();
    assert!(
        err <= tol,
        "{what}: got {actual:.16e}, expected {expected:.16e} (|err| = {err:.3e} > tol = {tol:.3e})"
    );
}

/// SplitMix64: a tiny seeded generator, so every test history is reproducible.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * ((self.next_u64() >> 11) as Real / (1u64 << 53) as Real)
    }
    /// 3×3 matrix with entries uniform in [−a, a).
    pub fn matrix(&mut self, a: Real) -> Mat3 {
        Mat3::from_fn(|_, _| self.uniform(-a, a))
    }
    /// A rotation with angle up to π about a random axis.
    pub fn rotation(&mut self) -> Mat3 {
        let axis = nalgebra::Vector3::new(
            self.uniform(-1.0, 1.0),
            self.uniform(-1.0, 1.0),
            self.uniform(-1.0, 1.0),
        );
        let angle = self.uniform(-3.1, 3.1);
        *nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).matrix()
    }
}

pub fn material(t: GranuleType) -> Material {
    t.params().validate().expect("preset is valid")
}

pub fn material_with(p: MaterialParams) -> Material {
    p.validate().expect("test parameters are valid")
}

/// a1(η), a2(η) written out independently of the kernel (physics.md §1.1).
pub fn a1_a2(p: &MaterialParams, eta: Real) -> (Real, Real) {
    if eta >= 1.0 {
        (0.0, 1.0)
    } else {
        (
            p.cp * (1.0 - eta * eta),
            (eta * eta - p.eta_c * p.eta_c) / (1.0 - p.eta_c * p.eta_c),
        )
    }
}

/// φ(τ, η)/((2/3)a2σy²) computed from the stress alone.
pub fn normalised_phi(p: &MaterialParams, tau: &Voigt, j: Real) -> Real {
    let (a1, a2) = a1_a2(p, p.eta0 / j);
    let scale = 2.0 / 3.0 * a2 * p.yield_stress_pa * p.yield_stress_pa;
    let beta = norm(&deviator(tau));
    let alpha = trace(tau);
    (beta * beta + a1 / 3.0 * alpha * alpha - scale) / scale
}

/// A generated sphere mesh in owned buffers (test side only: the kernel
/// itself never allocates).
pub struct OwnedMesh {
    pub size: granbed_kernel::mesh::sphere::MeshSize,
    pub positions: Vec<[Real; 3]>,
    pub hexes: Vec<[u32; 8]>,
    pub quads: Vec<[u32; 4]>,
    pub node_quads: Vec<[u32; 4]>,
}

pub fn sphere_mesh(p: &granbed_kernel::mesh::sphere::SphereMeshParams) -> OwnedMesh {
    use granbed_kernel::mesh::sphere::{MeshBuffers, generate};
    let size = p.size().expect("valid resolution");
    let mut mesh = OwnedMesh {
        size,
        positions: vec![[0.0; 3]; size.nodes],
        hexes: vec![[0; 8]; size.hexes],
        quads: vec![[0; 4]; size.quads],
        node_quads: vec![[0; 4]; size.surface_nodes],
    };
    let mut scratch = vec![0; size.scratch];
    generate(
        p,
        &mut MeshBuffers {
            positions: &mut mesh.positions,
            hexes: &mut mesh.hexes,
            quads: &mut mesh.quads,
            node_quads: &mut mesh.node_quads,
            scratch: &mut scratch,
        },
    )
    .expect("mesh generates");
    mesh
}

/// The element data of an [`OwnedMesh`] (test side), for a
/// `ReferenceMesh` over it.
pub struct ElementData {
    pub elements: Vec<granbed_kernel::element::reference::HexReference>,
    pub batches: Vec<granbed_kernel::element::batch::ElementBatch>,
    pub node_volume: Vec<Real>,
}

impl ElementData {
    /// The reference mesh of `mesh` (whose data this is) as the element
    /// passes read it.
    pub fn reference<'a>(
        &'a self,
        mesh: &'a OwnedMesh,
    ) -> granbed_kernel::mesh::reference::ReferenceMesh<'a> {
        granbed_kernel::mesh::reference::ReferenceMesh {
            mesh: mesh.view(),
            node_quads: &mesh.node_quads,
            elements: &self.elements,
            batches: &self.batches,
            node_volume: &self.node_volume,
        }
    }
}

impl OwnedMesh {
    pub fn hex_coords(&self, e: usize) -> [[Real; 3]; 8] {
        core::array::from_fn(|i| self.positions[self.hexes[e][i] as usize])
    }

    pub fn view(&self) -> granbed_kernel::mesh::octant::MeshView<'_> {
        granbed_kernel::mesh::octant::MeshView {
            positions: &self.positions,
            hexes: &self.hexes,
            quads: &self.quads,
            surface_nodes: self.size.surface_nodes,
        }
    }

    /// Element data, lumped volumes and the batches of the one-point element.
    pub fn element_data(&self) -> ElementData {
        use granbed_kernel::element::batch::{ElementBatch, batch_count, regroup};
        let first = granbed_kernel::element::reference::hex_reference(&self.hex_coords(0)).unwrap();
        let mut elements = vec![first; self.hexes.len()];
        let mut node_volume = vec![0.0; self.positions.len()];
        granbed_kernel::mesh::reference::compute_element_data(
            &self.view(),
            &mut elements,
            &mut node_volume,
        )
        .unwrap();
        let mut batches = vec![ElementBatch::ZERO; batch_count(elements.len())];
        regroup(&elements, &mut batches).unwrap();
        ElementData {
            elements,
            batches,
            node_volume,
        }
    }
}
