//! The element stresses of a granule (`granule::forces::element_stresses`,
//! what the bed's snapshots show): in a homogeneous deformation every
//! element of either formulation carries the material point's stress —
//! the neo-Hookean closed form while elastic (physics.md §1.7 C1), a stress
//! on the yield surface when the trial state lies beyond it (C4), and the
//! volume ratio det F — and the stored states are only read. Deformed
//! unevenly, each element's σ v is the virial Σ_I x_I ⊗ f_I of its internal
//! forces (the average-stress theorem the bed's axial check relies on).

mod common;

use common::{a1_a2, material, material_with, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::granule::forces::{
    ElementKind, ElementSettings, ElementStress, ForcesError, element_stresses,
};
use granbed_kernel::material::{GranuleType, Material};
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::tensor::{VOIGT_IDENTITY, Voigt};

const KINDS: [ElementKind; 2] = [ElementKind::OnePoint, ElementKind::FBar];

fn settings(kind: ElementKind) -> ElementSettings {
    ElementSettings {
        kind,
        update: Default::default(),
        hourglass_kappa: 0.05,
    }
}

/// det of a 3×3 matrix given by rows.
fn det(f: &[[Real; 3]; 3]) -> Real {
    f[0][0] * (f[1][1] * f[2][2] - f[1][2] * f[2][1])
        - f[0][1] * (f[1][0] * f[2][2] - f[1][2] * f[2][0])
        + f[0][2] * (f[1][0] * f[2][1] - f[1][1] * f[2][0])
}

/// The element stresses of the coarse sphere mesh moved by x = F X from
/// virgin states (C_p⁻¹ = 1 at every point).
fn stresses(mat: &Material, kind: ElementKind, f: &[[Real; 3]; 3]) -> Vec<Voigt> {
    let mesh = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let data = mesh.element_data();
    let x: Vec<[Real; 3]> = mesh
        .positions
        .iter()
        .map(|p| core::array::from_fn(|a| (0..3).map(|b| f[a][b] * p[b]).sum()))
        .collect();
    let cp_inv = vec![VOIGT_IDENTITY; mesh.hexes.len() * settings(kind).points_per_element()];
    let mut out = vec![ElementStress::default(); mesh.hexes.len()];
    element_stresses(
        &data.reference(&mesh),
        mat,
        &settings(kind),
        &x,
        &cp_inv,
        &mut out,
    )
    .unwrap();
    assert!(cp_inv.iter().all(|c| *c == VOIGT_IDENTITY));
    // Every element's volume ratio is det F.
    let j = det(f);
    for (e, o) in out.iter().enumerate() {
        assert!(
            (o.j - j).abs() <= 1e-13,
            "{kind:?} element {e}: J = {}, det F = {j}",
            o.j
        );
    }
    out.iter().map(|o| o.sigma).collect()
}

/// Voigt pairs `[xx, yy, zz, yz, xz, xy]`.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];

/// C1 per element: σ = [μ(b − 1) + λJ(J − 1) 1]/J with b = F Fᵀ, written out
/// here, for a stretch with shear and J ≈ 0.97, below the yield stress.
#[test]
fn an_elastic_homogeneous_deformation_gives_the_closed_form_in_every_element() {
    let mut p = GranuleType::B2.params();
    p.yield_stress_pa = 1e12;
    let mat = material_with(p);
    let f = [
        [0.99, 0.004, -0.002],
        [0.003, 0.985, 0.001],
        [0.0, -0.005, 0.995],
    ];
    let j = det(&f);
    let expected: Voigt = PAIRS.map(|(a, b)| {
        let bab: Real = (0..3).map(|k| f[a][k] * f[b][k]).sum();
        let delta = if a == b { 1.0 } else { 0.0 };
        (mat.mu * (bab - delta) + mat.lambda * j * (j - 1.0) * delta) / j
    });
    let scale = expected.iter().fold(0.0, |m: Real, s| m.max(s.abs()));
    for kind in KINDS {
        for (e, s) in stresses(&mat, kind, &f).iter().enumerate() {
            for k in 0..6 {
                assert!(
                    (s[k] - expected[k]).abs() <= 1e-10 * scale,
                    "{kind:?} element {e} component {k}: {} against {}",
                    s[k],
                    expected[k]
                );
            }
        }
    }
}

/// C4 per element: a 6 % compression of virgin B2 points lies beyond the
/// yield surface; every element's τ = Jσ is returned onto it,
/// |φ| ≤ 1e-12 (2/3)a2σy² with a1, a2 at η = η0/J written out here, and
/// all elements agree (the deformation is homogeneous).
#[test]
fn a_trial_state_beyond_yield_is_returned_onto_the_surface() {
    let mat = material(GranuleType::B2);
    let f = [[0.99, 0.0, 0.0], [0.0, 0.99, 0.0], [0.0, 0.0, 0.94]];
    let j = det(&f);
    let (a1, a2) = a1_a2(&mat.params, mat.params.eta0 / j);
    let scale = 2.0 / 3.0 * a2 * mat.params.yield_stress_pa * mat.params.yield_stress_pa;
    for kind in KINDS {
        let sigma = stresses(&mat, kind, &f);
        for (e, s) in sigma.iter().enumerate() {
            let tau = s.map(|v| v * j);
            let tr = tau[0] + tau[1] + tau[2];
            let dev2 = (0..3).map(|k| (tau[k] - tr / 3.0).powi(2)).sum::<Real>()
                + 2.0 * (3..6).map(|k| tau[k] * tau[k]).sum::<Real>();
            let phi = dev2 + a1 / 3.0 * tr * tr - scale;
            assert!(
                phi.abs() <= 1e-12 * scale,
                "{kind:?} element {e}: φ/scale = {:e}",
                phi / scale
            );
            assert!(tr < 0.0, "{kind:?} element {e}: not compressive, {s:?}");
            for k in 0..6 {
                assert!(
                    (s[k] - sigma[0][k]).abs() <= 1e-9 * tr.abs(),
                    "{kind:?} element {e}: {s:?} against {:?}",
                    sigma[0]
                );
            }
        }
    }
}

#[test]
fn the_stress_buffer_is_checked() {
    let mesh = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let data = mesh.element_data();
    let h = mesh.hexes.len();
    let mut out = vec![ElementStress::default(); h - 1];
    let err = element_stresses(
        &data.reference(&mesh),
        &material(GranuleType::B2),
        &settings(ElementKind::OnePoint),
        &mesh.positions,
        &vec![VOIGT_IDENTITY; h],
        &mut out,
    )
    .unwrap_err();
    assert_eq!(
        err,
        ForcesError::BufferLength {
            buffer: "out",
            expected: h,
            got: h - 1
        }
    );
}

/// In an uneven (non-affine), plastic deformation of the mesh, each
/// element's σ v equals the virial Σ_I x_I ⊗ f_I of the forces its pass
/// computes from the same states (v = J V0): the one-point element without
/// hourglass forces (κ = 0), and F-bar, whose Gauss points differ, so that
/// a stress averaged with other weights than their volumes misses it.
#[test]
fn each_element_stress_is_the_virial_of_its_forces() {
    use granbed_kernel::element::fbar::fbar_forces;
    use granbed_kernel::element::force::hex_forces;
    let mesh = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let data = mesh.element_data();
    let mat = material(GranuleType::B2);
    let mut rng = common::Rng::new(7);
    // 8 % axial compression with node jitter of 3 % of the radius.
    let x: Vec<[Real; 3]> = mesh
        .positions
        .iter()
        .map(|p| {
            let j: [Real; 3] = core::array::from_fn(|_| rng.uniform(-15e-6, 15e-6));
            [p[0] + j[0], p[1] + j[1], 0.92 * p[2] + j[2]]
        })
        .collect();
    for kind in KINDS {
        let mut s = settings(kind);
        s.hourglass_kappa = 0.0;
        let points = s.points_per_element();
        let cp_inv = vec![VOIGT_IDENTITY; mesh.hexes.len() * points];
        let mut out = vec![ElementStress::default(); mesh.hexes.len()];
        element_stresses(&data.reference(&mesh), &mat, &s, &x, &cp_inv, &mut out).unwrap();
        let mut plastic = 0;
        for (e, (hex, o)) in mesh.hexes.iter().zip(&out).enumerate() {
            let xe: [[Real; 3]; 8] = core::array::from_fn(|i| x[hex[i] as usize]);
            let (f, v) = match kind {
                ElementKind::OnePoint => {
                    let r = &data.elements[e];
                    let mut c = VOIGT_IDENTITY;
                    let h = hex_forces(&mat, &s.update, 0.0, r, &xe, &mut c).unwrap();
                    plastic += usize::from(h.info.plastic);
                    (h.f, h.j * r.volume)
                }
                ElementKind::FBar => {
                    let xr = mesh.hex_coords(e);
                    let mut c = [VOIGT_IDENTITY; 8];
                    let h = fbar_forces(&mat, &s.update, &xr, &xe, &mut c).unwrap();
                    plastic += usize::from(h.plastic_points > 0);
                    let v0: Real = data.elements[e].volume;
                    (h.f, o.j * v0)
                }
            };
            let scale = o.sigma.iter().fold(0.0, |m: Real, t| m.max(t.abs())) * v;
            for (k, &(a, b)) in PAIRS.iter().enumerate() {
                let virial: Real = (0..8).map(|i| xe[i][a] * f[i][b]).sum();
                assert!(
                    (virial - o.sigma[k] * v).abs() <= 1e-10 * scale,
                    "{kind:?} element {e} ({a}{b}): virial {virial:e} against σv {:e}",
                    o.sigma[k] * v
                );
            }
        }
        assert!(plastic > 0, "{kind:?}: no element yielded");
    }
}
