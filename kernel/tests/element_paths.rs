//! The one-point element loop gives the same bits on every path: element by
//! element, in portable batches and in AVX2 batches (when the processor has
//! it) — forces, energies, diagnostics and the stored states, through
//! elastic and plastic steps with lanes of both kinds in one batch, for a
//! count of elements that leaves a remainder, and on failure (the same
//! element reported, the same states left behind); and so does a granule's
//! assembly of them (`internal_forces_on`), whose sink takes a batch's
//! forces straight from its lanes.

mod common;

use common::{Rng, material, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::constitutive::UpdateError;
use granbed_kernel::constitutive::update::{check_input, input_is_valid, trial};
use granbed_kernel::element::batch::{
    BATCH, ElementBatch, ElementPath, batch_count, has_avx2, one_point_elements, regroup, sink,
};
use granbed_kernel::element::force::HexForces;
use granbed_kernel::element::reference::{HexReference, hex_reference};
use granbed_kernel::granule::forces::{
    ElementFailure, ElementKind, ElementSettings, ForcesError, internal_forces_on,
};
use granbed_kernel::material::GranuleType;
use granbed_kernel::mesh::reference::ReferenceMesh;
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::tensor::{VOIGT_IDENTITY, Voigt};

/// The paths, each with its reference data regrouped (`true`) or gathered
/// by every batch.
const PATHS: [(ElementPath, bool); 4] = [
    (ElementPath::Scalar, false),
    (ElementPath::Batched, true),
    (ElementPath::Avx2, true),
    (ElementPath::Avx2, false),
];

/// Everything an element hands to the loop, as bits.
fn bits(e: usize, out: &HexForces) -> Vec<u64> {
    let mut v = vec![e as u64];
    v.extend(out.f.iter().flatten().map(|x| x.to_bits()));
    v.extend(out.tau.iter().map(|x| x.to_bits()));
    v.extend(
        [
            out.hourglass_energy,
            out.j,
            out.plastic_dissipation,
            out.info.eps,
            out.info.delta,
            out.info.gamma,
            out.info.eta,
            out.info.je,
            out.info.residual,
            out.info.coefficients.a1,
            out.info.coefficients.a2,
        ]
        .map(Real::to_bits),
    );
    v.push(u64::from(out.info.coefficients.a2_clamped));
    v.push(out.info.method as u64);
    v.push(u64::from(out.info.plastic));
    v.push(u64::from(out.info.iterations));
    v
}

struct Pass {
    result: Result<(), ForcesError>,
    outputs: Vec<Vec<u64>>,
    plastic: usize,
}

fn run(
    (path, regrouped): (ElementPath, bool),
    hexes: &[[u32; 8]],
    refs: &[HexReference],
    x: &[[Real; 3]],
    cp: &mut [Voigt],
) -> Pass {
    let mat = material(GranuleType::B2);
    let mut batches = Vec::new();
    if regrouped {
        batches = vec![ElementBatch::ZERO; batch_count(refs.len())];
        regroup(refs, &mut batches).unwrap();
    }
    let mut outputs = Vec::new();
    let mut plastic = 0;
    let result = one_point_elements(
        path,
        &mat,
        &Default::default(),
        0.05,
        hexes,
        refs,
        &batches,
        x,
        cp,
        &mut sink(|e, _, out| {
            plastic += usize::from(out.info.plastic);
            outputs.push(bits(e, out));
        }),
    );
    Pass {
        result,
        outputs,
        plastic,
    }
}

/// The reference `positions` under a uniaxial strain `c` along z with a
/// shear of 0.2 c, and a node jitter of 2 % of the standard granule's
/// element (1 mm / 8), so that neighbouring elements differ.
fn strained(positions: &[[Real; 3]], c: Real, rng: &mut Rng) -> Vec<[Real; 3]> {
    let size = 1.0e-3 / 8.0;
    positions
        .iter()
        .map(|p| {
            [
                p[0] + 0.2 * c * p[2] + rng.uniform(-0.02, 0.02) * size,
                p[1] + rng.uniform(-0.02, 0.02) * size,
                p[2] * (1.0 - c) + rng.uniform(-0.02, 0.02) * size,
            ]
        })
        .collect()
}

/// One step of every path at positions `x` from its own `states` (one per
/// entry of [`PATHS`]): checks that each path succeeds and hands over,
/// element by element, and stores the scalar path's bits; returns the
/// scalar pass.
fn every_path_alike(
    step: usize,
    hexes: &[[u32; 8]],
    refs: &[HexReference],
    x: &[[Real; 3]],
    states: &mut [Vec<Voigt>],
) -> Pass {
    let mut passes: Vec<Pass> = PATHS
        .iter()
        .zip(states.iter_mut())
        .map(|(&path, cp)| run(path, hexes, refs, x, cp))
        .collect();
    let scalar = &passes[0];
    assert!(scalar.result.is_ok(), "step {step}: {:?}", scalar.result);
    for (path, pass) in PATHS.iter().zip(&passes).skip(1) {
        assert_eq!(pass.result, scalar.result, "{path:?}, step {step}");
        assert_eq!(pass.outputs.len(), hexes.len(), "{path:?}, step {step}");
        for (a, b) in pass.outputs.iter().zip(&scalar.outputs) {
            assert_eq!(a, b, "{path:?}, step {step}, element {}", b[0]);
        }
    }
    for cp in &states[1..] {
        let same = cp
            .iter()
            .flatten()
            .zip(states[0].iter().flatten())
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "stored states differ at step {step}");
    }
    passes.swap_remove(0)
}

#[test]
fn every_path_gives_the_scalar_bits_through_elastic_and_plastic_steps() {
    if !has_avx2() {
        eprintln!("no AVX2 here: the Avx2 entries run the portable batches");
    }
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    // 1279 elements: 319 full batches and a remainder of 3.
    let count = mesh.hexes.len() - 1;
    assert_ne!(count % BATCH, 0);
    let hexes = &mesh.hexes[..count];
    let refs: Vec<HexReference> = (0..count)
        .map(|e| hex_reference(&mesh.hex_coords(e)).unwrap())
        .collect();
    let mut states: Vec<Vec<Voigt>> = PATHS.iter().map(|_| vec![VOIGT_IDENTITY; count]).collect();
    let mut rng = Rng::new(7);
    let (mut mixed_batches, mut plastic_steps) = (0, 0);
    for step in 1..=40 {
        // Uniaxial strain to 20 % with shear.
        let x = strained(&mesh.positions, 0.005 * step as Real, &mut rng);
        let scalar = &every_path_alike(step, hexes, &refs, &x, &mut states);
        if scalar.plastic > 0 {
            plastic_steps += 1;
            // Batches with both elastic and plastic lanes.
            mixed_batches += scalar
                .outputs
                .chunks(BATCH)
                .filter(|b| {
                    let p = b.iter().filter(|o| o[o.len() - 2] == 1).count();
                    p > 0 && p < b.len()
                })
                .count();
        }
    }
    assert!(plastic_steps >= 10, "only {plastic_steps} plastic steps");
    assert!(
        mixed_batches > 0,
        "no batch mixed elastic and plastic lanes"
    );
}

/// Runs every path on positions `x` where element `bad` fails (lane 2 of
/// the second batch), and checks that each reports it with an error that
/// `expected` accepts and leaves the scalar path's states behind; returns
/// the scalar pass and its states.
fn fails_alike(
    hexes: &[[u32; 8]],
    refs: &[HexReference],
    x: &[[Real; 3]],
    bad: usize,
    expected: fn(&UpdateError) -> bool,
) -> (Pass, Vec<Voigt>) {
    // Lanes 0 and 1 were evaluated side by side with it, and must be
    // updated by the redo alone.
    assert_eq!(bad / BATCH, 1);
    assert_eq!(bad % BATCH, 2);
    let mut reference: Option<(Pass, Vec<Voigt>)> = None;
    for path in PATHS {
        let mut cp = vec![VOIGT_IDENTITY; hexes.len()];
        let pass = run(path, hexes, refs, x, &mut cp);
        match &pass.result {
            Err(ForcesError::Element(ElementFailure { element, error })) if expected(error) => {
                assert_eq!(*element, bad, "{path:?}: element {element}")
            }
            other => panic!("{path:?}: expected element {bad} to fail, got {other:?}"),
        }
        match &reference {
            None => reference = Some((pass, cp)),
            Some((scalar, scalar_cp)) => {
                assert_eq!(pass.result, scalar.result, "{path:?}");
                assert_eq!(pass.outputs, scalar.outputs, "{path:?}");
                let bits =
                    |c: &[Voigt]| c.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&cp), bits(scalar_cp), "{path:?}: states left behind");
            }
        }
    }
    reference.unwrap()
}

/// The standard mesh and the reference data of its first four batches
/// and one element more (the scalar tail): the elements the failure tests
/// run.
fn first_elements() -> (common::OwnedMesh, Vec<HexReference>) {
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let refs = (0..4 * BATCH + 1)
        .map(|e| hex_reference(&mesh.hex_coords(e)).unwrap())
        .collect();
    (mesh, refs)
}

#[test]
fn a_failing_element_is_reported_alike_and_leaves_the_same_states() {
    let (mesh, refs) = first_elements();
    let count = refs.len();
    let hexes = &mesh.hexes[..count];
    // Compress 25 % (plastic), then flip element 6 (inside the second
    // batch) through its centre: J < 0 there.
    let mut x: Vec<[Real; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p[0], p[1], 0.75 * p[2]])
        .collect();
    let bad = 6;
    let centre: [Real; 3] =
        core::array::from_fn(|a| hexes[bad].iter().map(|&n| x[n as usize][a]).sum::<Real>() / 8.0);
    let mut flipped = x.clone();
    for &n in &hexes[bad][..4] {
        let p = &mut flipped[n as usize];
        p[2] = 2.0 * centre[2] - p[2];
    }
    let (scalar, cp) = fails_alike(hexes, &refs, &flipped, bad, |e| {
        matches!(e, UpdateError::InvertedDeformation { .. })
    });
    assert!(
        scalar.plastic > 0,
        "the elements before the failure yielded"
    );
    assert!(cp.iter().any(|c| c != &VOIGT_IDENTITY));
    // A NaN coordinate, at a node element 6 has and no element before it:
    // the batch's verdict rejects the lane (its F and J are NaN), and the
    // redo names the error. (An infinite entry of F that leaves J = +∞ is
    // the case only the verdict's test of F catches: `element::batch`'s
    // unit test.)
    let node = hexes[bad]
        .iter()
        .find(|n| hexes[..bad].iter().all(|h| !h.contains(n)))
        .expect("element 6 has a node of its own among the first elements");
    x[*node as usize][1] = Real::NAN;
    fails_alike(hexes, &refs, &x, bad, |e| {
        matches!(e, UpdateError::NonFinite)
    });
}

/// Buffers that do not fit the hexes are refused by name before any
/// element is evaluated, on every path (they indexed out of bounds).
#[test]
fn buffers_that_do_not_fit_the_hexes_are_refused_by_name() {
    let (mesh, refs) = first_elements();
    let count = refs.len();
    let hexes = &mesh.hexes[..count];
    let x = mesh.positions.clone();
    let mut cp = vec![VOIGT_IDENTITY; count];
    for path in PATHS {
        assert_eq!(
            run(path, hexes, &refs[..count - 1], &x, &mut cp).result,
            Err(ForcesError::BufferLength {
                buffer: "refs",
                expected: count,
                got: count - 1
            })
        );
        let mut short = vec![VOIGT_IDENTITY; count + 1];
        let pass = run(path, hexes, &refs, &x, &mut short);
        assert_eq!(
            pass.result,
            Err(ForcesError::BufferLength {
                buffer: "cp_inv",
                expected: count,
                got: count + 1
            })
        );
        assert!(pass.outputs.is_empty(), "{path:?}: nothing evaluated");
        let id = hexes.as_flattened().iter().copied().max().unwrap();
        let few = &x[..id as usize];
        assert_eq!(
            run(path, hexes, &refs, few, &mut cp).result,
            Err(ForcesError::NodeId {
                id,
                nodes: id as usize
            })
        );
    }
    assert!(cp.iter().all(|c| c == &VOIGT_IDENTITY), "no state touched");
}

/// A stored state that is valid (positive definite, det C_p⁻¹ = 1) but so
/// stretched that the trial stress b = F C_p⁻¹ Fᵀ overflows fails its
/// element as non-finite on every path, the states untouched: the batch
/// has no test of φ^tr of its own, its corrector cannot return the lane,
/// and the redo element by element names it (it had read as "no
/// convergence").
#[test]
fn an_overflowing_trial_state_is_non_finite_on_every_path() {
    let (mesh, refs) = first_elements();
    let count = refs.len();
    let hexes = &mesh.hexes[..count];
    let bad = 6;
    let stretched: Voigt = [1e300, 1e-300, 1.0, 0.0, 0.0, 0.0];
    for path in PATHS {
        let mut cp = vec![VOIGT_IDENTITY; count];
        cp[bad] = stretched;
        let pass = run(path, hexes, &refs, &mesh.positions, &mut cp);
        assert_eq!(
            pass.result,
            Err(ForcesError::Element(ElementFailure {
                element: bad,
                error: UpdateError::NonFinite
            })),
            "{path:?}"
        );
        assert!(cp[..bad].iter().all(|c| *c == VOIGT_IDENTITY), "{path:?}");
        assert_eq!(cp[bad], stretched, "{path:?}");
    }
}

/// The kernel's own `cpuid`/`xgetbv` detection agrees with the standard
/// library's.
#[test]
fn avx2_detection_agrees_with_std_and_picks_the_fastest_path() {
    #[cfg(target_arch = "x86_64")]
    assert_eq!(has_avx2(), std::is_x86_feature_detected!("avx2"));
    #[cfg(not(target_arch = "x86_64"))]
    assert!(!has_avx2());
    assert_eq!(ElementPath::fastest() == ElementPath::Avx2, has_avx2());
}

/// Regrouped reference data of the wrong length, or of another mesh with
/// as many elements, are not used (no panic, no other bits): the batches
/// gather their lanes instead.
#[test]
fn regrouped_data_of_the_wrong_length_or_mesh_are_ignored() {
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let count = 3 * BATCH;
    let hexes = &mesh.hexes[..count];
    let refs: Vec<HexReference> = (0..count)
        .map(|e| hex_reference(&mesh.hex_coords(e)).unwrap())
        .collect();
    let x: Vec<[Real; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p[0], p[1], 0.8 * p[2]])
        .collect();
    let mat = material(GranuleType::B2);
    // Two batches, of elements 4…11: valid geometry, but the wrong one
    // for batch 0 — used, it would change the forces.
    let mut short = vec![ElementBatch::ZERO; batch_count(count - BATCH)];
    regroup(&refs[BATCH..], &mut short).unwrap();
    // Three batches of the elements after these: the right length, the
    // wrong mesh.
    let others: Vec<HexReference> = (count..2 * count)
        .map(|e| hex_reference(&mesh.hex_coords(e)).unwrap())
        .collect();
    let mut other = vec![ElementBatch::ZERO; batch_count(count)];
    regroup(&others, &mut other).unwrap();
    let mut outputs: Vec<Vec<Vec<u64>>> = Vec::new();
    for batches in [&[][..], &short[..], &other[..]] {
        let mut cp = vec![VOIGT_IDENTITY; count];
        let mut out = Vec::new();
        one_point_elements(
            ElementPath::Batched,
            &mat,
            &Default::default(),
            0.05,
            hexes,
            &refs,
            batches,
            &x,
            &mut cp,
            &mut |e: usize, _: &[u32; 8], o: &HexForces| out.push(bits(e, o)),
        )
        .unwrap();
        outputs.push(out);
    }
    assert_eq!(outputs[0].len(), count);
    assert_eq!(outputs[0], outputs[1]);
    assert_eq!(outputs[0], outputs[2]);
}

/// Lanes whose relative density is past 1 (von Mises, radial return),
/// just below it, or so low that a2 is clamped give the scalar bits on
/// every path: the yield test's branches run per lane after the batch's
/// arithmetic. B2 (η0 = 0.8) in a radial field ramped over 40 steps, which
/// shrinks the core by 0.9 (J ≈ 0.73, η ≈ 1.1) and stretches the shell by
/// up to 1.65 (J ≈ 4.5, η below η_c = 0.2).
#[test]
fn lanes_past_eta_one_or_with_a_clamped_a2_give_the_scalar_bits() {
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let count = mesh.hexes.len();
    let hexes = &mesh.hexes[..];
    let refs: Vec<HexReference> = (0..count)
        .map(|e| hex_reference(&mesh.hex_coords(e)).unwrap())
        .collect();
    let radius = 0.5e-3;
    let mut states: Vec<Vec<Voigt>> = PATHS.iter().map(|_| vec![VOIGT_IDENTITY; count]).collect();
    // Which lanes the field made: η from the outputs' bits (`bits`'s order).
    let eta = |o: &Vec<u64>| Real::from_bits(o[1 + 24 + 6 + 6]);
    let clamped = |o: &Vec<u64>| o[1 + 24 + 6 + 11] == 1;
    let (mut von_mises, mut near_one, mut clamp, mut mixed) = (0, 0, 0, 0);
    let steps = 40;
    for step in 1..=steps {
        let ramp = step as Real / steps as Real;
        let x: Vec<[Real; 3]> = mesh
            .positions
            .iter()
            .map(|p| {
                let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() / radius;
                let t = ((r - 0.25) / 0.6).clamp(0.0, 1.0);
                let s = 0.9 + 0.75 * t * t * (3.0 - 2.0 * t);
                p.map(|c| c * (1.0 + ramp * (s - 1.0)))
            })
            .collect();
        let scalar = &every_path_alike(step, hexes, &refs, &x, &mut states);
        von_mises += scalar.outputs.iter().filter(|o| eta(o) >= 1.0).count();
        near_one += scalar
            .outputs
            .iter()
            .filter(|o| (0.95..1.0).contains(&eta(o)))
            .count();
        clamp += scalar.outputs.iter().filter(|o| clamped(o)).count();
        mixed += scalar
            .outputs
            .chunks(BATCH)
            .filter(|b| b.iter().any(|o| eta(o) >= 1.0) && b.iter().any(|o| eta(o) < 1.0))
            .count();
    }
    assert!(
        von_mises > 0 && near_one > 0 && clamp > 0 && mixed > 0,
        "lanes past 1: {von_mises}, just below 1: {near_one}, clamped: {clamp}, batches across 1: {mixed}"
    );
}

/// A granule's assembled forces and summary are the same bits on every
/// path, through elastic and plastic steps: the batch hands its forces to
/// the assembly from the lanes (`Sink::batch`), the element by element
/// loop as arrays, and each must add them node by node in element order.
#[test]
fn the_assembled_forces_are_the_same_on_every_path() {
    let mesh = sphere_mesh(&SphereMeshParams::standard());
    let data = mesh.element_data();
    let reference = ReferenceMesh {
        mesh: mesh.view(),
        node_quads: &mesh.node_quads,
        elements: &data.elements,
        batches: &data.batches,
        node_volume: &data.node_volume,
    };
    let mat = material(GranuleType::B2);
    let settings = ElementSettings {
        kind: ElementKind::OnePoint,
        update: Default::default(),
        hourglass_kappa: 0.05,
    };
    let paths = [ElementPath::Scalar, ElementPath::Batched, ElementPath::Avx2];
    let mut states: Vec<Vec<Voigt>> = paths
        .iter()
        .map(|_| vec![VOIGT_IDENTITY; mesh.hexes.len()])
        .collect();
    let mut rng = Rng::new(11);
    let mut plastic_steps = 0;
    for step in 1..=20 {
        let x = strained(&mesh.positions, 0.01 * step as Real, &mut rng);
        let mut results = Vec::new();
        for (&path, cp) in paths.iter().zip(states.iter_mut()) {
            let mut f = vec![[Real::NAN; 3]; x.len()];
            let s = internal_forces_on(path, &reference, &mat, &settings, &x, cp, &mut f).unwrap();
            let mut bits: Vec<u64> = f.iter().flatten().map(|v| v.to_bits()).collect();
            bits.extend([s.hourglass_energy, s.plastic_dissipation, s.min_j].map(Real::to_bits));
            bits.extend([
                s.plastic_elements as u64,
                u64::from(s.max_iterations),
                s.a2_clamped as u64,
            ]);
            results.push(bits);
            if path == ElementPath::Scalar && s.plastic_elements > 0 {
                plastic_steps += 1;
            }
        }
        for (path, r) in paths.iter().zip(&results).skip(1) {
            assert!(
                r == &results[0],
                "{path:?} differs from the scalar path at step {step}"
            );
        }
    }
    assert!(plastic_steps >= 5, "only {plastic_steps} plastic steps");
}

/// The input checks, which the scalar element (`check_input`) and the
/// batch (`input_is_valid`, one verdict for its lanes) share, against the
/// rule written out here: accepted exactly when F is finite, J > 0,
/// 0 < det C_p⁻¹ < ∞ and η is finite, for every combination of ordinary and
/// special values (NaN, ±∞, ±0, subnormal, the largest finite); otherwise
/// the error of the first failed test, in the documented order.
#[test]
fn the_input_checks_accept_exactly_the_valid_inputs_and_name_the_first_failure() {
    use core::cmp::Ordering::Greater;
    let mat = material(GranuleType::B2);
    let specials = [
        1.0,
        0.5,
        -1.0,
        0.0,
        -0.0,
        f64::MIN_POSITIVE / 4.0,
        f64::MAX,
        -f64::MAX,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];
    let positive = |v: Real| v.partial_cmp(&0.0) == Some(Greater);
    let mut counts = [0; 4];
    // φ^tr: finite or −∞ (an infinite yield stress), and not (NaN, +∞ of
    // an overflowing trial stress).
    let phis = [-3.0e8, f64::NEG_INFINITY, f64::NAN, f64::INFINITY];
    for f_finite in [true, false] {
        for &j in &specials {
            for &det_c in &specials {
                for &eta in &specials {
                    for &phi in &phis {
                        // A trial state built from the identity, its J,
                        // det C_p⁻¹ and η then set to the values under test,
                        // with φ^tr given.
                        let f = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                        let mut t = trial(&mat, &f, &VOIGT_IDENTITY);
                        (t.j, t.det_cp_inv, t.eta) = (j, det_c, eta);
                        let expected = if !f_finite {
                            Some(UpdateError::NonFinite)
                        } else if !positive(j) {
                            Some(UpdateError::InvertedDeformation { j })
                        } else if !positive(det_c) || det_c.is_infinite() {
                            Some(UpdateError::InvalidState { det: det_c })
                        } else if eta.is_nan() || eta.is_infinite() {
                            Some(UpdateError::InvertedDeformation { j })
                        } else if phi.is_nan() || phi == f64::INFINITY {
                            Some(UpdateError::NonFinite)
                        } else {
                            None
                        };
                        let what = format!(
                            "F finite {f_finite}, J {j:e}, det C_p⁻¹ {det_c:e}, η {eta:e}, \
                         φ {phi:e}"
                        );
                        let got = check_input(f_finite, &t, phi);
                        match expected {
                            None => assert_eq!(got, Ok(()), "{what}"),
                            // Compared as text: the errors carry a NaN J or det.
                            Some(e) => assert_eq!(
                                format!("{got:?}"),
                                format!("{:?}", Err::<(), _>(e)),
                                "{what}"
                            ),
                        }
                        assert_eq!(
                            input_is_valid(f_finite, j, det_c, eta) && phi < f64::INFINITY,
                            expected.is_none(),
                            "{what}"
                        );
                        counts[match expected {
                            None => 0,
                            Some(UpdateError::NonFinite) => 1,
                            Some(UpdateError::InvalidState { .. }) => 2,
                            Some(_) => 3,
                        }] += 1;
                    }
                }
            }
        }
    }
    // Every outcome occurs: 2 × 11³ × 4 cases.
    assert!(counts.iter().all(|&c| c > 0), "{counts:?}");
    assert_eq!(counts.iter().sum::<usize>(), 2 * 11 * 11 * 11 * 4);
}
