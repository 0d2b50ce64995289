//! The element pass checks its buffers against the mesh before it runs
//! (the crate's slice-length policy): a wrong length or a node id beyond
//! the nodes is an error naming the buffer, never a panic and never a
//! pass that silently skips elements.

mod common;

use common::{material, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::granule::forces::{
    ElementKind, ElementSettings, ForcesError, elastic_energy, internal_forces,
};
use granbed_kernel::material::GranuleType;
use granbed_kernel::mesh::octant::MeshView;
use granbed_kernel::mesh::reference::ReferenceMesh;
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::tensor::{VOIGT_IDENTITY, Voigt};

struct Fixture {
    mesh: common::OwnedMesh,
    elements: Vec<granbed_kernel::element::reference::HexReference>,
    batches: Vec<granbed_kernel::element::batch::ElementBatch>,
    node_volume: Vec<Real>,
}

fn fixture() -> Fixture {
    let mesh = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let data = mesh.element_data();
    Fixture {
        mesh,
        elements: data.elements,
        batches: data.batches,
        node_volume: data.node_volume,
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

#[test]
fn an_hourglass_coefficient_out_of_range_is_an_error() {
    let fx = fixture();
    let (h, n) = (fx.mesh.hexes.len(), fx.mesh.positions.len());
    for kappa in [Real::NAN, -5.0, 1.5] {
        let mut cp = vec![VOIGT_IDENTITY; h];
        let mut f = vec![[0.0; 3]; n];
        let err = internal_forces(
            &fx.reference(&fx.mesh.hexes),
            &material(GranuleType::B2),
            &ElementSettings {
                hourglass_kappa: kappa,
                ..settings(ElementKind::OnePoint)
            },
            &fx.mesh.positions,
            &mut cp,
            &mut f,
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                ForcesError::InvalidParameter {
                    field: "hourglass_kappa",
                    ..
                }
            ),
            "{err}"
        );
    }
}

/// The halves of a step check the granule's buffers and the step sizes
/// before they write anything: a short buffer or a NaN Δt is an error,
/// where a slice used to panic and a NaN step to make the motion NaN.
#[test]
fn a_step_checks_its_buffers_and_step_sizes() {
    use granbed_kernel::granule::dynamics::{
        GranuleBuffers, Loads, StepSizes, correct, predict, predict_rigid,
    };
    let fx = fixture();
    let (h, n) = (fx.mesh.hexes.len(), fx.mesh.positions.len());
    let mat = material(GranuleType::B2);
    let reference = fx.reference(&fx.mesh.hexes);
    let one_point = settings(ElementKind::OnePoint);
    let loads = Loads {
        gravity_m_s2: 0.0,
        damping_c: 0.0,
        rigid_modes: true,
        selective_mass_factor: 1.0,
    };
    let good = StepSizes {
        dt_prev: 1e-7,
        dt: 1e-7,
    };
    let z = [0.0; 3];
    let (mut x, mut v, mut vs, mut xp) = (vec![z; n], vec![z; n], vec![z; n], vec![z; n]);
    let (mut fi, mut fc, mut fd) = (vec![z; n], vec![z; n], vec![z; n]);
    let (mut m, mut fixed, mut cp) = (vec![0.0; n], vec![0u8; n], vec![VOIGT_IDENTITY; h]);
    let mut b = GranuleBuffers {
        x: &mut x,
        v: &mut v,
        v_star: &mut vs,
        x_pred: &mut xp,
        f_int: &mut fi,
        f_c: &mut fc,
        f_d: &mut fd,
        mass: &mut m,
        fixed: &mut fixed,
        cp_inv: &mut cp,
    };
    b.reset(&reference, &mat);
    predict(&reference, &mat, &one_point, &mut b, good, &loads).unwrap();
    correct(&mut b, good, &loads).unwrap();
    for bad in [
        StepSizes {
            dt: Real::NAN,
            ..good
        },
        StepSizes { dt: 0.0, ..good },
        StepSizes {
            dt_prev: Real::INFINITY,
            ..good
        },
    ] {
        let before = b.x.to_vec();
        for err in [
            predict(&reference, &mat, &one_point, &mut b, bad, &loads).unwrap_err(),
            predict_rigid(&mut b, bad, &loads).unwrap_err(),
            correct(&mut b, bad, &loads).unwrap_err(),
        ] {
            assert!(matches!(err, ForcesError::InvalidParameter { .. }), "{err}");
        }
        assert_eq!(b.x, &before[..], "nothing written");
    }
    // A velocity buffer one node short.
    let mut short_v = vec![z; n - 1];
    let mut b = GranuleBuffers {
        v: &mut short_v,
        ..b
    };
    for err in [
        predict(&reference, &mat, &one_point, &mut b, good, &loads).unwrap_err(),
        predict_rigid(&mut b, good, &loads).unwrap_err(),
        correct(&mut b, good, &loads).unwrap_err(),
    ] {
        assert_eq!(
            err,
            ForcesError::BufferLength {
                buffer: "v",
                expected: n,
                got: n - 1
            }
        );
    }
    // A position buffer one node short: reset fills what both hold (it
    // panicked in copy_from_slice), and the step refuses the buffers.
    let (mut short_x, mut full_v) = (vec![z; n - 1], vec![z; n]);
    let mut b = GranuleBuffers {
        x: &mut short_x,
        v: &mut full_v,
        ..b
    };
    b.reset(&reference, &mat);
    assert_eq!(b.x, &reference.mesh.positions[..n - 1]);
    let r = predict(&reference, &mat, &one_point, &mut b, good, &loads);
    assert!(matches!(r, Err(ForcesError::BufferLength { .. })), "{r:?}");
}
