//! Oracles of the one-point hex element (physics.md §2.4: E1, E2, C6/§2.4.4)
//! and of the selective damping (§4.5: T2).

// Index loops over xyz components read best here.
#![allow(clippy::needless_range_loop)]

mod common;

use common::{Rng, assert_close, material, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::constitutive::UpdateOptions;
use granbed_kernel::element::force::{hex_forces, mean_deformation_gradient};
use granbed_kernel::element::hex8::{
    GAUSS_GRADIENTS, HexCoords, NODE_SIGNS, gauss_points, shape_gradients,
};
use granbed_kernel::element::reference::hex_reference;
use granbed_kernel::granule::damping::{damping_forces, rigid_motion};
use granbed_kernel::material::GranuleType;
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::tensor::{Mat3, VOIGT_IDENTITY};

fn apply(f: &Mat3, c: [Real; 3], x: &[Real; 3]) -> [Real; 3] {
    core::array::from_fn(|a| (0..3).map(|b| f[(a, b)] * x[b]).sum::<Real>() + c[a])
}

/// A 2×2×2 patch of hexes on a 3×3×3 node lattice whose interior node (and
/// all others) are perturbed in the reference configuration.
fn distorted_patch(rng: &mut Rng) -> (Vec<[Real; 3]>, Vec<[u32; 8]>) {
    let h = 1e-4;
    let mut x = Vec::new();
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                let jitter = if (i, j, k) == (1, 1, 1) {
                    0.25 * h
                } else {
                    0.1 * h
                };
                x.push([
                    i as Real * h + rng.uniform(-jitter, jitter),
                    j as Real * h + rng.uniform(-jitter, jitter),
                    k as Real * h + rng.uniform(-jitter, jitter),
                ]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + 3 * (j + 3 * k)) as u32;
    let mut hexes = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..2 {
                hexes.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    (x, hexes)
}

/// E1 patch test: x = FX + c on a distorted patch gives F̄ = F in every
/// element, q_α = 0 (zero hourglass energy) and zero force on the interior
/// node (1e-13 relative to the element forces), for elastic and plastic F.
#[test]
fn e1_patch_test() {
    let mut rng = Rng::new(11);
    let mat = material(GranuleType::B1);
    for _ in 0..20 {
        let (xref, hexes) = distorted_patch(&mut rng);
        let f = Mat3::identity() + rng.matrix(0.15);
        let c = [
            rng.uniform(-1e-3, 1e-3),
            rng.uniform(-1e-3, 1e-3),
            rng.uniform(-1e-3, 1e-3),
        ];
        let mut force = [[0.0; 3]; 27];
        let mut scale: Real = 0.0;
        for hex in &hexes {
            let xe: HexCoords = core::array::from_fn(|i| xref[hex[i] as usize]);
            let r = hex_reference(&xe).unwrap();
            let cur: HexCoords = core::array::from_fn(|i| apply(&f, c, &xe[i]));
            let fbar = mean_deformation_gradient(&r, &cur);
            assert!((fbar - f).norm() < 1e-13, "F-bar = F");
            let mut state = VOIGT_IDENTITY;
            let out =
                hex_forces(&mat, &UpdateOptions::default(), 0.05, &r, &cur, &mut state).unwrap();
            assert!(
                out.hourglass_energy <= 1e-26 * r.volume * mat.mu,
                "q = 0: E_hg = {:e}",
                out.hourglass_energy
            );
            for (i, id) in hex.iter().enumerate() {
                for a in 0..3 {
                    force[*id as usize][a] += out.f[i][a];
                    scale = scale.max(out.f[i][a].abs());
                }
            }
        }
        let interior = force[13];
        for a in 0..3 {
            assert!(
                interior[a].abs() <= 1e-13 * scale,
                "interior force {:e} vs {scale:e}",
                interior[a]
            );
        }
    }
}

/// E2: translation plus any finite rotation of the reference element gives
/// zero internal and hourglass force (round-off relative to μ·area).
#[test]
fn e2_rigid_motion_gives_zero_force() {
    let mut rng = Rng::new(12);
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let mat = material(GranuleType::C2);
    for e in (0..mesh.size.hexes).step_by(37) {
        let xe = mesh.hex_coords(e);
        let r = hex_reference(&xe).unwrap();
        let q = rng.rotation();
        let c = [rng.uniform(-1.0, 1.0), 0.3, -2.0];
        let cur: HexCoords = core::array::from_fn(|i| apply(&q, c, &xe[i]));
        let mut state = VOIGT_IDENTITY;
        let out = hex_forces(&mat, &UpdateOptions::default(), 0.05, &r, &cur, &mut state).unwrap();
        let scale = mat.mu * r.volume.powf(2.0 / 3.0);
        for fi in out.f {
            for a in 0..3 {
                assert!(
                    fi[a].abs() < 1e-10 * scale,
                    "rigid-motion force {:e}",
                    fi[a]
                );
            }
        }
    }
}

/// §2.4 oracle 4: objectivity of the element forces, f(Qx) = Q f(x), for a
/// deformed, plastically loaded element (1e-12 relative), including the
/// hourglass part.
#[test]
fn element_forces_are_objective() {
    let mut rng = Rng::new(13);
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let mat = material(GranuleType::A1);
    for e in (0..mesh.size.hexes).step_by(53) {
        let xe = mesh.hex_coords(e);
        let r = hex_reference(&xe).unwrap();
        // A deformation with an hourglass component: affine map plus noise.
        let f = Mat3::identity() + rng.matrix(0.2) - Mat3::identity() * 0.1;
        let cur: HexCoords = core::array::from_fn(|i| {
            let y = apply(&f, [0.0; 3], &xe[i]);
            [
                y[0] + rng.uniform(-2e-6, 2e-6),
                y[1] + rng.uniform(-2e-6, 2e-6),
                y[2],
            ]
        });
        let q = rng.rotation();
        let rotated: HexCoords = core::array::from_fn(|i| apply(&q, [0.0; 3], &cur[i]));
        let (mut s1, mut s2) = (VOIGT_IDENTITY, VOIGT_IDENTITY);
        let a = hex_forces(&mat, &UpdateOptions::default(), 0.05, &r, &cur, &mut s1).unwrap();
        let b = hex_forces(&mat, &UpdateOptions::default(), 0.05, &r, &rotated, &mut s2).unwrap();
        assert!(a.hourglass_energy > 0.0 && a.info.plastic);
        assert_close(
            "hourglass energy",
            b.hourglass_energy,
            a.hourglass_energy,
            1e-12,
            0.0,
        );
        let scale =
            a.f.iter()
                .flatten()
                .fold(0.0 as Real, |m, x| m.max(x.abs()));
        for i in 0..8 {
            let qf = apply(&q, [0.0; 3], &a.f[i]);
            for k in 0..3 {
                assert_close("Q f", b.f[i][k], qf[k], 0.0, 1e-12 * scale);
            }
        }
    }
}

/// The hourglass force is the gradient of the hourglass energy (central
/// differences, 1e-6 relative), so hourglass control is conservative: at a
/// small hourglass amplitude (±3 µm on a ~0.1 mm element, the quadratic
/// term) and at a large one (±30 µm, where the quartic stiffening leads).
#[test]
fn hourglass_force_is_the_energy_gradient() {
    let mut rng = Rng::new(14);
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let mat = material(GranuleType::A1);
    let elastic = granbed_kernel::material::MaterialParams {
        yield_stress_pa: Real::INFINITY,
        ..mat.params
    }
    .validate()
    .unwrap();
    let xe = mesh.hex_coords(700);
    let r = hex_reference(&xe).unwrap();
    for noise in [3e-6, 30e-6] {
        let cur: HexCoords = core::array::from_fn(|i| {
            core::array::from_fn(|a| xe[i][a] + rng.uniform(-noise, noise))
        });
        let energy = |x: &HexCoords| {
            let mut s = VOIGT_IDENTITY;
            hex_forces(&elastic, &UpdateOptions::default(), 0.05, &r, x, &mut s)
                .unwrap()
                .hourglass_energy
        };
        let mut s = VOIGT_IDENTITY;
        let with = hex_forces(&elastic, &UpdateOptions::default(), 0.05, &r, &cur, &mut s).unwrap();
        let mut s = VOIGT_IDENTITY;
        let without =
            hex_forces(&elastic, &UpdateOptions::default(), 0.0, &r, &cur, &mut s).unwrap();
        let h = 1e-9;
        for i in 0..8 {
            for a in 0..3 {
                let (mut p, mut m) = (cur, cur);
                p[i][a] += h;
                m[i][a] -= h;
                let fd = (energy(&p) - energy(&m)) / (2.0 * h);
                let f_hg = with.f[i][a] - without.f[i][a];
                assert_close("dE_hg/dx", fd, f_hg, 1e-6, 1e-9 * f_hg.abs().max(1e-12));
            }
        }
    }
}

/// T2: damping forces sum to zero with zero moment about the centre of mass
/// (1e-14 relative); a rigid translation plus spin is not damped at all.
#[test]
fn t2_damping_spares_rigid_motion() {
    let mut rng = Rng::new(15);
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let n = mesh.positions.len();
    let mass: Vec<Real> = (0..n).map(|_| rng.uniform(1e-10, 3e-10)).collect();
    let x = &mesh.positions;
    let omega = [30.0, -12.0, 7.0];
    let vc = [0.01, -0.02, 0.005];
    let rigid: Vec<[Real; 3]> = x
        .iter()
        .map(|p| {
            [
                vc[0] + omega[1] * p[2] - omega[2] * p[1],
                vc[1] + omega[2] * p[0] - omega[0] * p[2],
                vc[2] + omega[0] * p[1] - omega[1] * p[0],
            ]
        })
        .collect();
    let mut f_d = vec![[0.0; 3]; n];
    damping_forces(&mass, x, &rigid, 1e5, true, &mut f_d);
    let m_total: Real = mass.iter().sum();
    let vmax = 0.05;
    for f in &f_d {
        for a in 0..3 {
            assert!(
                f[a].abs() < 1e-12 * 1e5 * m_total * vmax,
                "rigid motion damped: {:e}",
                f[a]
            );
        }
    }
    // A random (deformational + rigid) field: zero net force and moment.
    let v: Vec<[Real; 3]> = (0..n)
        .map(|i| core::array::from_fn(|a| rigid[i][a] + rng.uniform(-0.01, 0.01)))
        .collect();
    damping_forces(&mass, x, &v, 1e5, true, &mut f_d);
    let centre = rigid_motion(&mass, x, &v).centre;
    let scale: Real = f_d
        .iter()
        .map(|f| f[0].abs() + f[1].abs() + f[2].abs())
        .sum();
    let mut sum = [0.0; 3];
    let mut moment = [0.0; 3];
    for (p, f) in x.iter().zip(&f_d) {
        let r = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
        for a in 0..3 {
            sum[a] += f[a];
        }
        moment[0] += r[1] * f[2] - r[2] * f[1];
        moment[1] += r[2] * f[0] - r[0] * f[2];
        moment[2] += r[0] * f[1] - r[1] * f[0];
    }
    for a in 0..3 {
        assert!(
            sum[a].abs() < 1e-14 * scale,
            "net damping force {:e}",
            sum[a]
        );
        assert!(
            moment[a].abs() < 1e-14 * scale * 0.5e-3,
            "net damping moment {:e}",
            moment[a]
        );
    }
}

/// The F-bar element's forces are the exact gradient of its stored energy
/// Σ_g det J_g ψ(F̄_g) for an elastic material (central differences, 1e-6
/// relative): the formula f_I = Σ det J_g [τ̄ b_Ig + ⅓ tr τ̄ (b_I0 − b_Ig)] is the
/// consistent variation.
#[test]
fn fbar_forces_are_the_energy_gradient() {
    use granbed_kernel::element::fbar::{fbar_elastic_energy, fbar_forces};
    let mut rng = Rng::new(16);
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let elastic = granbed_kernel::material::MaterialParams {
        yield_stress_pa: Real::INFINITY,
        ..GranuleType::B2.params()
    }
    .validate()
    .unwrap();
    let opts = UpdateOptions::default();
    for e in [0, 600, 1279] {
        let xr = mesh.hex_coords(e);
        let f = Mat3::identity() + rng.matrix(0.1);
        let cur: HexCoords = core::array::from_fn(|i| {
            let y = apply(&f, [0.0; 3], &xr[i]);
            core::array::from_fn(|a| y[a] + rng.uniform(-3e-6, 3e-6))
        });
        let mut states = [VOIGT_IDENTITY; 8];
        let out = fbar_forces(&elastic, &opts, &xr, &cur, &mut states).unwrap();
        let scale = out
            .f
            .iter()
            .flatten()
            .fold(0.0 as Real, |m, x| m.max(x.abs()));
        let h = 1e-10;
        for i in 0..8 {
            for a in 0..3 {
                let (mut p, mut m) = (cur, cur);
                p[i][a] += h;
                m[i][a] -= h;
                let id = [VOIGT_IDENTITY; 8];
                let fd = (fbar_elastic_energy(&elastic, &xr, &p, &id)
                    - fbar_elastic_energy(&elastic, &xr, &m, &id))
                    / (2.0 * h);
                assert_close("dW/dx (F-bar)", out.f[i][a], fd, 0.0, 1e-6 * scale);
            }
        }
    }
}

/// F-bar patch test and rigid motion: affine motion gives F̄ = F at every
/// Gauss point and zero interior force; a rigid motion gives zero force.
#[test]
fn fbar_patch_and_rigid_motion() {
    use granbed_kernel::element::fbar::fbar_forces;
    let mut rng = Rng::new(17);
    let mat = material(GranuleType::B1);
    let opts = UpdateOptions::default();
    for _ in 0..10 {
        let (xref, hexes) = distorted_patch(&mut rng);
        let f = Mat3::identity() + rng.matrix(0.15);
        let mut force = [[0.0; 3]; 27];
        let mut scale: Real = 0.0;
        for hex in &hexes {
            let xe: HexCoords = core::array::from_fn(|i| xref[hex[i] as usize]);
            let cur: HexCoords = core::array::from_fn(|i| apply(&f, [1e-3, 0.0, -2e-3], &xe[i]));
            let mut states = [VOIGT_IDENTITY; 8];
            let out = fbar_forces(&mat, &opts, &xe, &cur, &mut states).unwrap();
            assert!(
                states
                    .iter()
                    .all(|s| (0..6).all(|k| (s[k] - states[0][k]).abs() < 1e-12)),
                "uniform state"
            );
            for (i, id) in hex.iter().enumerate() {
                for a in 0..3 {
                    force[*id as usize][a] += out.f[i][a];
                    scale = scale.max(out.f[i][a].abs());
                }
            }
        }
        for a in 0..3 {
            assert!(
                force[13][a].abs() <= 1e-12 * scale,
                "interior force {:e}",
                force[13][a]
            );
        }
        let xe: HexCoords = core::array::from_fn(|i| xref[hexes[0][i] as usize]);
        let q = rng.rotation();
        let cur: HexCoords = core::array::from_fn(|i| apply(&q, [0.5, 0.5, 0.5], &xe[i]));
        let mut states = [VOIGT_IDENTITY; 8];
        let out = fbar_forces(&mat, &opts, &xe, &cur, &mut states).unwrap();
        for fi in out.f {
            for a in 0..3 {
                assert!(
                    fi[a].abs() < 1e-10 * mat.mu * 1e-8,
                    "rigid F-bar force {:e}",
                    fi[a]
                );
            }
        }
    }
}

/// The hourglass stiffness doubles at a nodal hourglass amplitude of
/// `HOURGLASS_STIFFENING_AMPLITUDE` × the element size and grows with its
/// square (a cube, a pure ξη hourglass mode, which leaves F̄ alone).
#[test]
fn hourglass_stiffening_follows_the_amplitude() {
    let side = 1e-4;
    let corners: HexCoords = NODE_SIGNS.map(|p| p.map(|c| 0.5 * side * c));
    let r = hex_reference(&corners).unwrap();
    let mat = material(GranuleType::B2);
    let mode = [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0];
    let force = |d: Real| {
        let x: HexCoords = core::array::from_fn(|i| {
            let mut p = corners[i];
            p[0] += d * mode[i];
            p
        });
        let mut s = VOIGT_IDENTITY;
        hex_forces(&mat, &UpdateOptions::default(), 0.05, &r, &x, &mut s)
            .unwrap()
            .f[0][0]
    };
    let a = granbed_kernel::element::force::HOURGLASS_STIFFENING_AMPLITUDE;
    let tiny = 1e-6 * side;
    for rel in [0.02, 0.1, 0.3] {
        let d = rel * side;
        let linear = force(tiny) * d / tiny;
        let factor = force(d) / linear;
        let want = 1.0 + (rel / a) * (rel / a);
        assert!(
            (factor / want - 1.0).abs() < 1e-6,
            "amplitude {rel}: stiffening {factor}, expected {want}"
        );
    }
}

/// `hex_volume` is `hex_reference`'s volume to the bit (the time-step
/// estimate relies on it to leave the runs unchanged) on jittered and
/// sheared hexes, and refuses an inverted one as `hex_reference` does.
#[test]
fn the_hex_volume_is_the_reference_volume_to_the_bit() {
    use granbed_kernel::element::reference::hex_volume;
    let mut rng = Rng::new(7);
    for _ in 0..200 {
        let shear = rng.uniform(-0.5, 0.5);
        let xe: HexCoords = core::array::from_fn(|i| {
            let s = NODE_SIGNS[i];
            [
                1e-4 * (s[0] + shear * s[2] + rng.uniform(-0.2, 0.2)),
                1e-4 * (s[1] + rng.uniform(-0.2, 0.2)),
                1e-4 * (s[2] + rng.uniform(-0.2, 0.2)),
            ]
        });
        let v = hex_volume(&xe).unwrap();
        assert_eq!(v.to_bits(), hex_reference(&xe).unwrap().volume.to_bits());
    }
    let mut inverted: HexCoords = core::array::from_fn(|i| NODE_SIGNS[i].map(|s| 1e-4 * s));
    inverted[6] = [-3e-4, -3e-4, -3e-4];
    assert_eq!(hex_volume(&inverted), None);
    assert!(hex_reference(&inverted).is_none());
    let mut nan: HexCoords = core::array::from_fn(|i| NODE_SIGNS[i].map(|s| 1e-4 * s));
    nan[3][1] = Real::NAN;
    assert_eq!(hex_volume(&nan), None);
}

/// The compile-time table of the shape gradients at the Gauss points (what
/// the quadrature, the time-step estimate and the worst-element check
/// read) is `shape_gradients` there, to the bit.
#[test]
fn the_gauss_gradient_table_is_the_shape_gradients_to_the_bit() {
    for (table, g) in GAUSS_GRADIENTS.iter().zip(gauss_points()) {
        let want = shape_gradients(g);
        for (t, w) in table.iter().flatten().zip(want.iter().flatten()) {
            assert_eq!(t.to_bits(), w.to_bits(), "at {g:?}");
        }
    }
}
