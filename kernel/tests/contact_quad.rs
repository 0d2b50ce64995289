//! Node-to-quad projection (physics.md §5.2): exact on planar quads, a true
//! minimum of the distance on warped ones, edge clamping, and the broad
//! phase against brute force.

use granbed_kernel::contact::broad::{
    Bound, BroadScratch, GranulePair, candidate_pairs, needs_rebuild,
};
use granbed_kernel::contact::quad::{project, project_clamped};
use granbed_kernel::rng::Rng;

type V = [f64; 3];

fn bilinear(x: &[V; 4], xi: f64, eta: f64) -> V {
    let n = granbed_kernel::contact::quad::weights(xi, eta);
    core::array::from_fn(|a| (0..4).map(|i| n[i] * x[i][a]).sum())
}

fn dist(a: &V, b: &V) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// The square [−1, 1]² at z = 0 with every corner coordinate moved by up
/// to ±warp/2.
fn warped_square(rng: &mut Rng, warp: f64) -> [V; 4] {
    let mut x = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    for c in &mut x {
        for v in c.iter_mut() {
            *v += warp * (rng.unit() - 0.5);
        }
    }
    x
}

/// A random point with |x|, |y| ≤ `half_width` and |z| ≤ 0.3.
fn point_near(rng: &mut Rng, half_width: f64) -> V {
    [
        2.0 * half_width * (rng.unit() - 0.5),
        2.0 * half_width * (rng.unit() - 0.5),
        0.6 * (rng.unit() - 0.5),
    ]
}

#[test]
fn planar_square_projection_is_exact() {
    let x = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 2.0, 0.0],
        [0.0, 2.0, 0.0],
    ];
    let p = [1.5, 0.5, -0.25];
    let pr = project(&p, &x).unwrap();
    assert!((pr.xi - 0.5).abs() < 1e-14 && (pr.eta + 0.5).abs() < 1e-14);
    assert!((pr.gap + 0.25).abs() < 1e-14, "gap {}", pr.gap);
    assert_eq!(pr.normal, [0.0, 0.0, 1.0]);
    assert!((pr.weights.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    // The weights interpolate the contact point.
    let xc = bilinear(&x, pr.xi, pr.eta);
    assert!(dist(&xc, &pr.point) < 1e-15);
}

#[test]
fn warped_quads_give_the_true_closest_point() {
    let mut rng = Rng::new(7);
    for _ in 0..500 {
        // A unit square with random warp and a point near it.
        let x = warped_square(&mut rng, 0.3);
        let p = point_near(&mut rng, 0.8);
        let pr = project(&p, &x).unwrap();
        let d = dist(&p, &pr.point);
        // No point of the (extended) surface on a fine grid is closer.
        let mut best = f64::INFINITY;
        for i in 0..=200 {
            for j in 0..=200 {
                let (s, t) = (-1.5 + 3.0 * i as f64 / 200.0, -1.5 + 3.0 * j as f64 / 200.0);
                best = best.min(dist(&p, &bilinear(&x, s, t)));
            }
        }
        assert!(d <= best + 1e-12, "Newton {d} vs grid {best}");
        // Stationarity: r ⟂ both tangents.
        assert!((pr.gap.abs() - d).abs() < 1e-9 * (1.0 + d));
    }
}

/// The returned (ξ, η) is a stationary point of the distance to round-off:
/// (X(ξ, η) − p)·X,ξ and ·X,η below 1e-13 of |X,ξ|² (unit-size quads, points
/// within a face size), on warped quads of every degree up to folded
/// ones. A search stopped after the first full Newton step below 1e-7
/// (error about its square) still passes, with 5e-15 at worst; one stopped
/// below 1e-6 leaves 3.5e-13 and fails (both tried, BENCHMARKS.md session
/// 24).
#[test]
fn the_projection_is_stationary_to_round_off() {
    let mut rng = Rng::new(11);
    let mut inside = 0;
    for k in 0..4000 {
        let x = warped_square(&mut rng, [0.05, 0.3, 0.8][k % 3]);
        let p = point_near(&mut rng, 1.0);
        let Some(pr) = project(&p, &x) else { continue };
        if pr.xi.abs() >= 3.9 || pr.eta.abs() >= 3.9 {
            continue; // held at the search box, not a stationary point
        }
        // Tangents of the bilinear map at (ξ, η).
        let d = |f: &dyn Fn(f64, f64) -> f64| -> [f64; 3] {
            core::array::from_fn(|a| {
                let c = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
                (0..4).map(|i| f(c[i][0], c[i][1]) * x[i][a]).sum()
            })
        };
        let t1 = d(&|a, b| 0.25 * a * (1.0 + b * pr.eta));
        let t2 = d(&|a, b| 0.25 * b * (1.0 + a * pr.xi));
        let r: V = core::array::from_fn(|a| bilinear(&x, pr.xi, pr.eta)[a] - p[a]);
        let dot = |u: &V, v: &V| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        for t in [t1, t2] {
            let g = dot(&r, &t).abs();
            assert!(g <= 1e-13 * dot(&t, &t), "case {k}: gradient {g:e}");
        }
        inside += usize::from(pr.xi.abs() <= 1.0 && pr.eta.abs() <= 1.0);
    }
    assert!(inside > 1000, "{inside} projections inside the face");
}

#[test]
fn clamped_projection_lands_on_the_nearest_edge() {
    let x = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let p = [1.5, 0.25, -0.1];
    let free = project(&p, &x).unwrap();
    assert!(!free.inside(1e-6));
    let pr = project_clamped(&p, &x).unwrap();
    assert!((pr.xi - 1.0).abs() < 1e-15 && (pr.eta + 0.5).abs() < 1e-12);
    assert!(dist(&pr.point, &[1.0, 0.25, 0.0]) < 1e-15);
}

#[test]
fn broad_phase_finds_exactly_the_brute_force_pairs() {
    let mut rng = Rng::new(3);
    let bounds: Vec<Bound> = (0..300)
        .map(|_| Bound {
            centre: [8.0 * rng.unit(), 8.0 * rng.unit(), 20.0 * rng.unit()],
            radius: 0.4 + 0.2 * rng.unit(),
        })
        .collect();
    let margin = 0.05;
    let mut head = vec![0; 8 * bounds.len()];
    let mut next = vec![0; bounds.len()];
    let mut out = vec![GranulePair { a: 0, b: 0 }; 10_000];
    let mut scratch = BroadScratch {
        head: &mut head,
        next: &mut next,
    };
    let n = candidate_pairs(&bounds, margin, &mut scratch, &mut out).unwrap();
    let mut brute = Vec::new();
    for i in 0..bounds.len() {
        for j in i + 1..bounds.len() {
            if dist(&bounds[i].centre, &bounds[j].centre)
                < bounds[i].radius + bounds[j].radius + margin
            {
                brute.push(GranulePair {
                    a: i as u32,
                    b: j as u32,
                });
            }
        }
    }
    assert!(!brute.is_empty());
    assert_eq!(&out[..n], &brute[..]);
    // A too-small output buffer is an error, not a silent truncation.
    let mut small = vec![GranulePair { a: 0, b: 0 }; n - 1];
    assert!(candidate_pairs(&bounds, margin, &mut scratch, &mut small).is_err());
    // Moving one granule by half the margin asks for a rebuild.
    let mut moved = bounds.clone();
    assert!(!needs_rebuild(&bounds, &moved, margin));
    moved[17].centre[0] += 0.5 * margin;
    assert!(needs_rebuild(&bounds, &moved, margin));
}

// Regressions found by `fuzz_inputs.rs` (issue #9).

/// A strongly warped, skewed face and a point 1.3 face sizes away: the
/// plain Newton iteration stopped at a point that was no minimum and
/// reported the node inside the face and 0.07 behind it (a false contact).
/// With the line search the projection descends: whatever it reports, a
/// point it calls inside is no farther than the true closest point of the
/// face (brute force on a 801² grid) allows.
#[test]
fn a_warped_skewed_face_reports_no_false_contact() {
    let q = [
        [0.7424753412673608, 0.07232429699752399, 0.7165678238745629],
        [
            -0.36059079505813646,
            -0.13149883626287498,
            0.7711372490669683,
        ],
        [-0.4108391457767893, -0.4457946524203274, 0.9745595219141283],
        [0.5951760674884068, 0.296419139561023, 0.8463376149920782],
    ];
    let p = [-0.34858909461025595, 0.6203624597902218, 1.91214975116203];
    let mut best = f64::INFINITY;
    for i in 0..=800 {
        for j in 0..=800 {
            let x = bilinear(&q, -1.0 + i as f64 / 400.0, -1.0 + j as f64 / 400.0);
            best = best.min(dist(&x, &p));
        }
    }
    let r = project(&p, &q).expect("a regular face");
    if r.inside(0.0) {
        assert!(
            dist(&r.point, &p) <= best * (1.0 + 1e-9),
            "inside at distance {} but the face's closest point is {best}",
            dist(&r.point, &p)
        );
    }
    // The closest point of the face is on its edge, 1.30 away: no contact.
    assert!(best > 1.29 && !(r.inside(0.0) && r.gap < 0.0 && r.gap > -0.3));
}

/// A face beyond f64's range gave a zero "unit" normal (|n|² overflowed);
/// now it is reported as unusable.
#[test]
fn a_face_too_large_for_f64_is_refused() {
    let q = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 5.158992707029342e19],
        [4.525196648703604e146, 0.0, 0.0],
    ];
    let p = [0.9557169300612098 * 4.525196648703604e146, 0.0, 0.0];
    if let Some(r) = project(&p, &q) {
        let n2: f64 = r.normal.iter().map(|v| v * v).sum();
        assert!((n2 - 1.0).abs() < 1e-9, "normal {:?}", r.normal);
    }
}

/// The sieve on a skewed face (the kind fuzzing found): a planar
/// parallelogram with e1 = (1, 0, 0), e2 = (0.95, 0.1, 0) and a node at
/// (ξ, η) = (0.9, 0.9), 0.01 behind it. The old parallelogram coordinate
/// (p − c)·e1/|e1|² = 0.9 + 0.9·0.95 = 1.755 exceeded the old limit 1.5 and
/// rejected this contact; the oblique coordinates give ξ = 0.9 exactly.
#[test]
fn the_sieve_passes_contacts_on_skewed_faces() {
    use granbed_kernel::contact::quad::QuadSieve;
    let (e1, e2) = ([1.0, 0.0, 0.0], [0.95, 0.1, 0.0]);
    let corner = |s1: f64, s2: f64| -> V { core::array::from_fn(|a| s1 * e1[a] + s2 * e2[a]) };
    let q = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    let p = [0.9 * 1.95, 0.09, -0.01];
    let r = project(&p, &q).unwrap();
    assert!(
        (r.xi - 0.9).abs() < 1e-12 && (r.eta - 0.9).abs() < 1e-12,
        "{r:?}"
    );
    assert!((r.gap + 0.01).abs() < 1e-12, "gap {}", r.gap);
    let sieve = QuadSieve::new(&q).unwrap();
    assert!(
        sieve.may_touch(&p, 0.02, 0.0),
        "the sieve rejected a contact"
    );
    // And it still rejects what is plainly out of reach.
    assert!(!sieve.may_touch(&[10.0, 10.0, -0.01], 0.02, 0.0));
    assert!(!sieve.may_touch(&[0.0, 0.0, -1.0], 0.02, 0.0));
}

/// A point 3e304 away from a face with one corner at 4e139: the line
/// search found no descent at the start, whose coordinates were so large
/// that the bilinear weights cancelled to a sum of 0. The reported
/// coordinates now stay in the iterates' box [−4, 4]².
#[test]
fn a_far_point_gets_bounded_coordinates_and_weights_that_sum_to_one() {
    let q = [
        [0.0, -0.9477576316510261, 0.0],
        [0.0, -0.6205348357968942, -0.16378925119772084],
        [0.0, 0.4276509334102136, -0.0946795611330926],
        [4.4579037026861536e139, 0.0, 0.0],
    ];
    let p = [0.0, -7.527417871229974e164 * 4.4579037026861536e139, 0.0];
    if let Some(r) = project(&p, &q) {
        assert!(r.xi.abs() <= 4.0 && r.eta.abs() <= 4.0, "{r:?}");
        let w: f64 = r.weights.iter().sum();
        assert!((w - 1.0).abs() < 1e-9, "weights sum to {w}");
    }
}
