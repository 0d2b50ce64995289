//! The element pass checks its buffers against the mesh before it runs
//! (the crate's slice-length policy): a wrong length or a node id beyond
//! the nodes is an error naming the buffer, never a panic and never a
//! pass that silently skips elements.

mod common;

use common::{material, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::element::batch::{ElementBatch, batch_count, regroup};
use granbed_kernel::element::reference::hex_reference;
use granbed_kernel::granule::forces::{
    ElementKind, ElementSettings, ForcesError, elastic_energy, internal_forces,
};
use granbed_kernel::material::GranuleType;
use granbed_kernel::mesh::octant::MeshView;
use granbed_kernel::mesh::reference::{ReferenceMesh, compute_element_data};
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::tensor::{VOIGT_IDENTITY, Voigt};

struct Fixture {
    mesh: common::OwnedMesh,
    elements: Vec<granbed_kernel::element::reference::HexReference>,
    batches: Vec<ElementBatch>,
    node_volume: Vec<Real>,
}

fn fixture() -> Fixture {
    let mesh = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let view = MeshView {
        positions: &mesh.positions,
        hexes: &mesh.hexes,
        quads: &mesh.quads,
        surface_nodes: mesh.size.surface_nodes,
    };
    let mut elements = vec![hex_reference(&mesh.hex_coords(0)).unwrap(); mesh.hexes.len()];
    let mut node_volume = vec![0.0; mesh.positions.len()];
    compute_element_data(&view, &mut elements, &mut node_volume).unwrap();
    let mut batches = vec![ElementBatch::ZERO; batch_count(elements.len())];
    regroup(&elements, &mut batches).unwrap();
    Fixture {
        mesh,
        elements,
        batches,
        node_volume,
    }
}

impl Fixture {
    fn reference<'a>(&'a self, hexes: &'a [[u32; 8]]) -> ReferenceMesh<'a> {
        ReferenceMesh {
            mesh: MeshView {
                positions: &self.mesh.positions,
                hexes,
                quads: &self.mesh.quads,
                surface_nodes: self.mesh.size.surface_nodes,
            },
            node_quads: &self.mesh.node_quads,
            elements: &self.elements,
            batches: &self.batches,
            node_volume: &self.node_volume,
        }
    }
}

fn settings(kind: ElementKind) -> ElementSettings {
    ElementSettings {
        kind,
        update: Default::default(),
        hourglass_kappa: 0.05,
    }
}

/// `internal_forces` on the undeformed mesh with `cp_inv` of `states`
/// entries, `f` of `forces` entries and the mesh's hexes `hexes`.
fn pass(
    fx: &Fixture,
    hexes: &[[u32; 8]],
    kind: ElementKind,
    states: usize,
    forces: usize,
) -> Result<(), ForcesError> {
    let mut cp: Vec<Voigt> = vec![VOIGT_IDENTITY; states];
    let mut f = vec![[0.0; 3]; forces];
    internal_forces(
        &fx.reference(hexes),
        &material(GranuleType::B2),
        &settings(kind),
        &fx.mesh.positions,
        &mut cp,
        &mut f,
    )
    .map(|_| ())
}

#[test]
fn consistent_buffers_pass() {
    let fx = fixture();
    let (h, n) = (fx.mesh.hexes.len(), fx.mesh.positions.len());
    pass(&fx, &fx.mesh.hexes, ElementKind::OnePoint, h, n).unwrap();
    pass(&fx, &fx.mesh.hexes, ElementKind::FBar, 8 * h, n).unwrap();
}

#[test]
fn a_short_state_buffer_is_an_error_not_a_skipped_element() {
    let fx = fixture();
    let (h, n) = (fx.mesh.hexes.len(), fx.mesh.positions.len());
    let expect = |expected, got| ForcesError::BufferLength {
        buffer: "cp_inv",
        expected,
        got,
    };
    assert_eq!(
        pass(&fx, &fx.mesh.hexes, ElementKind::OnePoint, h - 1, n),
        Err(expect(h, h - 1))
    );
    // F-bar holds eight states per element; one per element was accepted
    // before and evaluated an eighth of the mesh.
    assert_eq!(
        pass(&fx, &fx.mesh.hexes, ElementKind::FBar, h, n),
        Err(expect(8 * h, h))
    );
}

#[test]
fn node_buffers_of_the_wrong_length_are_errors() {
    let fx = fixture();
    let (h, n) = (fx.mesh.hexes.len(), fx.mesh.positions.len());
    assert_eq!(
        pass(&fx, &fx.mesh.hexes, ElementKind::OnePoint, h, n - 1),
        Err(ForcesError::BufferLength {
            buffer: "f",
            expected: n,
            got: n - 1
        })
    );
    let mut cp = vec![VOIGT_IDENTITY; h];
    let mut f = vec![[0.0; 3]; n];
    let err = internal_forces(
        &fx.reference(&fx.mesh.hexes),
        &material(GranuleType::B2),
        &settings(ElementKind::OnePoint),
        &fx.mesh.positions[..n - 1],
        &mut cp,
        &mut f,
    )
    .unwrap_err();
    assert!(
        matches!(err, ForcesError::BufferLength { buffer: "x", .. }),
        "{err}"
    );
}

#[test]
fn a_node_id_beyond_the_nodes_is_an_error() {
    let fx = fixture();
    let (h, n) = (fx.mesh.hexes.len(), fx.mesh.positions.len());
    let mut hexes = fx.mesh.hexes.clone();
    hexes[h / 2][5] = 99_999;
    for kind in [ElementKind::OnePoint, ElementKind::FBar] {
        let states = h * settings(kind).points_per_element();
        let err = pass(&fx, &hexes, kind, states, n).unwrap_err();
        assert_eq!(
            err,
            ForcesError::NodeId {
                id: 99_999,
                nodes: n
            }
        );
        assert!(err.to_string().contains("node 99999"), "{err}");
    }
}

#[test]
fn elastic_energy_checks_its_buffers_too() {
    let fx = fixture();
    let h = fx.mesh.hexes.len();
    let reference = fx.reference(&fx.mesh.hexes);
    let mat = material(GranuleType::B2);
    let one_point = settings(ElementKind::OnePoint);
    let x = &fx.mesh.positions;
    // Undeformed and unstrained: no stored energy (up to the round-off of
    // F = 1 from the mean gradients; μV0 ~ 1e-5 J here).
    let e = elastic_energy(&reference, &mat, &one_point, x, &vec![VOIGT_IDENTITY; h]).unwrap();
    assert!(e.abs() < 1e-18, "stored energy {e:e} J at rest");
    // An empty state buffer read as "no elements" gave 0 J before.
    assert_eq!(
        elastic_energy(&reference, &mat, &one_point, x, &[]),
        Err(ForcesError::BufferLength {
            buffer: "cp_inv",
            expected: h,
            got: 0
        })
    );
}
