//! The single-granule experiment against physics (physics.md §5.6, §7 item 7,
//! §8 K1–K3, P1) and against an established FE code (CalculiX), through the
//! same run loop the CLI uses.

use std::path::Path;

use granbed_cli::granule::run::run_platens;
use granbed_cli::model::{MeshLevel, OwnedReference, PlatenStore};
use granbed_kernel::Real;
use granbed_kernel::analysis::granule::yield_stress_estimate;
use granbed_kernel::material::{GranuleType, MaterialParams};
use granbed_kernel::scene::platens::{PlatenParams, PlatenSample, PlatenScene, Symmetry};

const R: Real = 0.5e-3;

fn mesh(level: MeshLevel, octant: bool) -> OwnedReference {
    OwnedReference::sphere(R, level, octant).unwrap()
}

fn run(params: PlatenParams, mesh: &OwnedReference) -> Vec<PlatenSample> {
    let result = run_platens(params, mesh, &mut |_, _| {}).unwrap();
    assert!(result.error.is_none(), "{:?}", result.error);
    result.samples
}

/// (approach x, mean platen force) of every sample.
fn curve(samples: &[PlatenSample]) -> Vec<(Real, Real)> {
    samples
        .iter()
        .map(|s| (s.approach_m, s.mean_force()))
        .collect()
}

/// Work ∫₀ˣ F dx of a piecewise-linear curve, J.
fn work(points: &[(Real, Real)], x_end: Real) -> Real {
    let mut w = 0.0;
    for pair in points.windows(2) {
        let ((x0, f0), (x1, mut f1)) = (pair[0], pair[1]);
        if x0 >= x_end {
            break;
        }
        let mut x1 = x1;
        if x1 > x_end {
            f1 = f0 + (f1 - f0) * (x_end - x0) / (x1 - x0);
            x1 = x_end;
        }
        w += 0.5 * (f0 + f1) * (x1 - x0);
    }
    w
}

/// Linear interpolation of F at approach `x`.
fn force_at(points: &[(Real, Real)], x: Real) -> Real {
    let k = points
        .iter()
        .position(|p| p.0 >= x)
        .expect("curve reaches x");
    let ((x0, f0), (x1, f1)) = (points[k - 1], points[k]);
    f0 + (f1 - f0) * (x - x0) / (x1 - x0)
}

/// §7 item 7 and issue #3: the octant with three symmetry planes gives the
/// full-sphere answer within 1 % (4x1 mesh: the symmetry argument does not
/// depend on the resolution) — every sample's force from 5 % strain on and σ_est.
#[test]
fn octant_equals_full_sphere() {
    let mat = GranuleType::B2.params().validate().unwrap();
    let mut p = PlatenParams::standard(mat);
    let octant = curve(&run(p, &mesh(MeshLevel::new(4, 1), true)));
    p.symmetry = Symmetry::Full;
    let full = curve(&run(p, &mesh(MeshLevel::new(4, 1), false)));
    assert_eq!(octant.len(), full.len());
    for (o, f) in octant.iter().zip(&full) {
        if o.0 >= 0.05e-3 {
            assert!(
                (o.1 / f.1 - 1.0).abs() < 0.01,
                "octant {} vs full {} at x = {}",
                o.1,
                f.1,
                o.0
            );
        }
    }
    let sigma = |c: &[(Real, Real)]| {
        yield_stress_estimate(c.iter().copied(), 2.0 * R, 0.1, 0.4)
            .unwrap()
            .0
    };
    assert!((sigma(&octant) / sigma(&full) - 1.0).abs() < 0.01);
}

/// Hertz force F = (4/3)E*√R (x/2)^{3/2} of a sphere between two plates, N.
fn hertz(e_star: Real, x: Real) -> Real {
    4.0 / 3.0 * e_star * R.sqrt() * (x / 2.0).powf(1.5)
}

/// An elastic granule (σy = ∞) between frictionless plates, compressed at
/// 2 mm/s with damping to `strain` on `level`: its (approach, force) curve.
fn elastic_curve(level: MeshLevel, strain: Real) -> (Vec<(Real, Real)>, Real) {
    let mat = MaterialParams {
        yield_stress_pa: Real::INFINITY,
        ..GranuleType::A3.params()
    }
    .validate()
    .unwrap();
    let mut p = PlatenParams::standard(mat);
    p.friction = 0.0;
    p.approach_speed_m_s = 2e-3;
    p.final_strain = strain;
    p.output_strain_interval = 0.0025;
    let e_star = mat.params.youngs_modulus_pa / (1.0 - mat.params.poisson_ratio.powi(2));
    (curve(&run(p, &mesh(level, true))), e_star)
}

/// K2 (§5.6 item 4): the elastic granule follows Hertz: 1.036 / 4.095 /
/// 11.58 mN at 2 / 5 / 10 % strain, within 20 / 15 / 15 %. On the standard
/// 8x2 mesh only the pole node touches the plate below 2 % strain (the first
/// ring of surface nodes, 0.1 mm from the axis, touches at 2 %), so the 2 %
/// point is checked on the 16x4 mesh, whose first ring touches at 0.5 %;
/// 5 and 10 % on the standard mesh.
#[test]
fn k2_elastic_granule_follows_hertz() {
    let (fine, e_star) = elastic_curve(MeshLevel::new(16, 4), 0.02);
    let (standard, _) = elastic_curve(MeshLevel::STANDARD, 0.1);
    for (c, strain, published, tol) in [
        (&fine, 0.02, 1.036e-3, 0.20),
        (&standard, 0.05, 4.095e-3, 0.15),
        (&standard, 0.10, 11.58e-3, 0.15),
    ] {
        let x = strain * 2.0 * R;
        let h = hertz(e_star, x);
        assert!(
            (h / published - 1.0).abs() < 1e-3,
            "Hertz formula {h} vs {published}"
        );
        let f = force_at(c, x);
        println!(
            "Hertz at {strain}: granbed {f:.4e} N, Hertz {h:.4e} N ({:+.1} %)",
            100.0 * (f / h - 1.0)
        );
        assert!((f / h - 1.0).abs() < tol, "strain {strain}: {f} vs {h}");
    }
}

/// K3 (§5.6 item 3): a granule resting on the lower platen under gravity
/// (full sphere, damped; the upper platen drifts away at 1 µm/s) presses on
/// it with its weight m g = ρ0 V_mesh g = 7.57 µN (η0 = 1), to 1 % in the
/// time average after the first 5 ms; the upper platen carries nothing. The
/// granule keeps rocking on its contact at about 1 kHz (that mode is nearly
/// a rigid translation, which the selective damping leaves alone), so the
/// force is averaged over ~25 periods: 30 ms with the physical masses, 95 ms
/// with masses ×10 (√10 slower), where gravity ÷10 must keep the weight.
/// K1: no node stays below the lower platen by more than round-off after the
/// corrector.
#[test]
fn k3_resting_granule_weighs_m_g_and_k1_no_penetration() {
    for (mass_scaling, duration_s) in [(1.0, 30e-3), (10.0, 95e-3)] {
        resting_granule(mass_scaling, duration_s);
    }
}

fn resting_granule(mass_scaling: Real, duration_s: Real) {
    let mat = GranuleType::A3.params().validate().unwrap();
    let m = mesh(MeshLevel::STANDARD, false);
    let weight = mat.density0 * m.view().volume() * 9.81;
    assert!((weight / 7.57e-6 - 1.0).abs() < 1e-3, "m g = {weight}");
    let mut p = PlatenParams::standard(mat);
    p.symmetry = Symmetry::Full;
    p.gravity_m_s2 = 9.81;
    p.mass_scaling = mass_scaling;
    p.approach_speed_m_s = 1e-6;
    p.final_strain = duration_s * p.approach_speed_m_s / (2.0 * R);
    p.output_strain_interval = 0.5e-6; // 0.5 ms windows
    let mut store = PlatenStore::new(&m, 1);
    let mut scene = PlatenScene::new(p, m.view(), store.buffers()).unwrap();
    let (mut impulse, mut span, mut upper) = (0.0, 0.0, 0.0 as Real);
    let mut previous_time = 0.0;
    let mut lowest: Real = 0.0;
    while !scene.finished() {
        if let Some(s) = scene.step().unwrap() {
            if s.time_s > 5e-3 {
                impulse += s.force_lower_n * (s.time_s - previous_time);
                span += s.time_s - previous_time;
                upper = upper.max(s.force_upper_n);
            }
            previous_time = s.time_s;
        }
        let floor = -R + 0.5 * p.approach_speed_m_s * scene.time();
        let min_z = scene
            .positions()
            .iter()
            .fold(Real::INFINITY, |a, x| a.min(x[2]));
        lowest = lowest.min(min_z - floor);
    }
    let mean = impulse / span;
    println!(
        "masses x{mass_scaling}: mean lower force {mean:.5e} N over {span:.4} s, m g {weight:.5e} N, upper {upper:e} N, deepest {lowest:e} m"
    );
    assert!(
        (mean / weight - 1.0).abs() < 0.01,
        "masses x{mass_scaling}: lower platen {mean} vs m g {weight}"
    );
    assert!(upper == 0.0, "upper platen {upper}");
    assert!(
        lowest >= -1e-12,
        "a node sank {lowest:e} m below the platen"
    );
}

fn fixture(name: &str) -> Vec<(Real, Real)> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures/peers/calculix")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<Real> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[1], v[2])
        })
        .collect()
}

/// Agreement with CalculiX 2.20 (C3D8R, implicit, NLGEOM; fixtures/peers/
/// calculix) for non-porous granules A3/B3/C3 at 5 mm/s, μ = 0.1: the work
/// ∫F dx up to 10/20/30/40 % strain within 5 % and σ_est within 5 %.
///
/// The work, not the point force, is compared: both curves rise in steps as
/// each ring of surface nodes (0.1 mm quads) touches the platen, and the
/// node-based kinematic contact picks a ring up at a slightly different strain
/// than CalculiX's penalty surface-to-surface contact (A3: 0.26 against 0.33),
/// so point forces differ by up to 7 % between the steps while the work and
/// the slope differ by less than 4 %.
#[test]
fn agrees_with_calculix() {
    let m = mesh(MeshLevel::STANDARD, true);
    for t in [GranuleType::A3, GranuleType::B3, GranuleType::C3] {
        let reference = fixture(&format!("reference_{t}.csv"));
        let ours = curve(&run(
            PlatenParams::standard(t.params().validate().unwrap()),
            &m,
        ));
        for strain in [0.1, 0.2, 0.3, 0.4] {
            let x = strain * 2.0 * R;
            let (w, w_ref) = (work(&ours, x), work(&reference, x));
            println!(
                "{t} work to {strain}: {:+.1} %, force {:+.1} %",
                100.0 * (w / w_ref - 1.0),
                100.0 * (force_at(&ours, x) / force_at(&reference, x) - 1.0)
            );
            assert!(
                (w / w_ref - 1.0).abs() < 0.05,
                "{t}: work to strain {strain}: {w} vs CalculiX {w_ref}"
            );
        }
        let sigma = |c: &[(Real, Real)]| {
            yield_stress_estimate(c.iter().copied(), 2.0 * R, 0.1, 0.4)
                .unwrap()
                .0
        };
        let (s, s_ref) = (sigma(&ours), sigma(&reference));
        println!(
            "{t} sigma_est {s:.0} Pa vs CalculiX {s_ref:.0} Pa ({:+.1} %)",
            100.0 * (s / s_ref - 1.0)
        );
        assert!(
            (s / s_ref - 1.0).abs() < 0.05,
            "{t}: sigma_est {s} vs CalculiX {s_ref}"
        );
    }
}

/// P1 / issue #3: σ_est converges with the mesh. B2 on the 4x1, 8x2 and 16x4
/// levels (at 20 mm/s to keep the 16x4 run short; the rate raises σ_est by
/// about 1 % against 5 mm/s on every level): the change from 8x2 to 16x4 is
/// less than a third of the change from 4x1 to 8x2 (second order would give
/// a quarter; measured at 5 mm/s: 41.49, 44.64, 45.52 kPa, ratio 3.6), and
/// under 3 %.
#[test]
fn sigma_est_converges_with_the_mesh() {
    let mat = GranuleType::B2.params().validate().unwrap();
    let mut p = PlatenParams::standard(mat);
    p.approach_speed_m_s = 20e-3;
    let sigma: Vec<Real> = [
        MeshLevel::new(4, 1),
        MeshLevel::STANDARD,
        MeshLevel::new(16, 4),
    ]
    .into_iter()
    .map(|level| {
        let c = curve(&run(p, &mesh(level, true)));
        yield_stress_estimate(c.iter().copied(), 2.0 * R, 0.1, 0.4)
            .unwrap()
            .0
    })
    .collect();
    println!("sigma_est 4x1 / 8x2 / 16x4: {sigma:?}");
    let (coarse, fine) = (sigma[1] - sigma[0], sigma[2] - sigma[1]);
    assert!(fine.abs() < coarse.abs() / 3.0, "not converging: {sigma:?}");
    assert!((sigma[2] / sigma[1] - 1.0).abs() < 0.03, "{sigma:?}");
}

/// A mesh that claims more surface nodes than it has nodes is refused by
/// the scene, naming the field: it had been accepted, and the first step
/// panicked slicing the surface (found by an embedding audit).
#[test]
fn a_scene_refuses_an_inconsistent_mesh() {
    use granbed_kernel::mesh::octant::MeshView;
    use granbed_kernel::mesh::reference::ReferenceMesh;
    use granbed_kernel::scene::platens::SceneError;
    let m = mesh(MeshLevel::STANDARD, true);
    let p = PlatenParams::standard(GranuleType::B2.params().validate().unwrap());
    let mut store = PlatenStore::new(&m, 1);
    let v = m.view();
    let bad = ReferenceMesh {
        mesh: MeshView {
            surface_nodes: v.mesh.positions.len() + 1,
            ..v.mesh
        },
        ..v
    };
    assert_eq!(bad.first_surface_node(), 0);
    let e = PlatenScene::new(p, bad, store.buffers())
        .err()
        .expect("an inconsistent mesh must be refused");
    assert!(matches!(e, SceneError::Mesh(_)), "{e}");
    assert!(e.to_string().contains("surface_nodes"), "{e}");
    // The same mesh as it is runs.
    let mut scene = PlatenScene::new(p, v, store.buffers()).unwrap();
    scene.step().unwrap();
}

/// The yield tolerance is checked where the element passes and the scene
/// take their settings, naming the field: NaN, negative or looser than
/// 1e-6 is refused (a negative one had sent an elastic point to the
/// corrector, which reported no convergence); 0 and the default pass.
#[test]
fn a_bad_yield_tolerance_is_refused_by_name() {
    use granbed_kernel::granule::forces::{ForcesError, internal_forces};
    use granbed_kernel::scene::platens::SceneError;
    let m = mesh(MeshLevel::STANDARD, true);
    let v = m.view();
    let mat = GranuleType::B2.params().validate().unwrap();
    for (tol, ok) in [
        (1e-12, true),
        (0.0, true),
        (1e-6, true),
        (Real::NAN, false),
        (-1e-9, false),
        (1e-3, false),
    ] {
        let mut p = PlatenParams::standard(mat);
        p.elements.update.yield_tolerance = tol;
        let mut store = PlatenStore::new(&m, 1);
        match PlatenScene::new(p, v, store.buffers()).map(|_| ()) {
            Ok(()) => assert!(ok, "{tol} accepted by the scene"),
            Err(SceneError::InvalidParameter { field, .. }) => {
                assert!(!ok, "{tol} refused by the scene");
                assert_eq!(field, "yield_tolerance");
            }
            Err(e) => panic!("{tol}: {e}"),
        }
        let x = v.mesh.positions.to_vec();
        let mut cp_inv = vec![[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]; v.mesh.hexes.len()];
        let mut f = vec![[0.0; 3]; x.len()];
        match internal_forces(&v, &mat, &p.elements, &x, &mut cp_inv, &mut f) {
            Ok(_) => assert!(ok, "{tol} accepted by the element pass"),
            Err(ForcesError::InvalidParameter { field, .. }) => {
                assert!(!ok, "{tol} refused by the element pass");
                assert_eq!(field, "yield_tolerance");
            }
            Err(e) => panic!("{tol}: {e}"),
        }
    }
}

/// A granule so soft that its stable time step would carry the platens
/// past the final strain in one step (E = 1e-3 Pa, the smallest allowed:
/// its waves travel at about 1 mm/s, slower than the platens) is stepped
/// at most `MAX_STRAIN_PER_STEP` at a time: it ends within one such step
/// of its final strain, with a sample every output interval. Before, one
/// step took it from 0 to 56 % strain.
#[test]
fn a_granule_softer_than_the_platens_are_fast_still_gives_a_curve() {
    use granbed_kernel::scene::platens::MAX_STRAIN_PER_STEP;
    let mut params = GranuleType::B2.params();
    params.youngs_modulus_pa = 1e-3;
    let mat = params.validate().unwrap();
    let m = mesh(MeshLevel::new(4, 1), true);
    let p = PlatenParams::standard(mat);
    let mut store = PlatenStore::new(&m, 1);
    let mut scene = PlatenScene::new(p, m.view(), store.buffers()).unwrap();
    let mut samples = 0;
    while !scene.finished() {
        if scene.step().unwrap().is_some() {
            samples += 1;
        }
    }
    let overshoot = scene.strain() - p.final_strain;
    assert!(
        (0.0..=MAX_STRAIN_PER_STEP * (1.0 + 1e-9)).contains(&overshoot),
        "ended at strain {} for a final strain of {}",
        scene.strain(),
        p.final_strain
    );
    let rows = (p.final_strain / p.output_strain_interval).round() as usize;
    assert!(
        samples + 1 >= rows,
        "{samples} samples for {rows} output intervals"
    );
    assert!(
        scene.steps() as Real >= p.final_strain / MAX_STRAIN_PER_STEP,
        "{} steps",
        scene.steps()
    );
}
