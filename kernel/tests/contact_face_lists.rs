//! Per-node face lists (`contact::face_lists`): detection through lists
//! built on an anchor gives the full pass's constraints to the bit while
//! no surface node has moved farther than the lists' drift — and does not
//! when the lists were built without that skin (so the comparison can fail).

mod common;

use common::{Rng, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::contact::broad::bounding_sphere;
use granbed_kernel::contact::face_lists::{
    AnchorSurface, FaceLists, FaceListsMut, ReachBox, build, drift, face_diagonal,
};
use granbed_kernel::contact::pair::{
    CandidateFace, Constraint, PairSettings, detect, detect_listed,
};
use granbed_kernel::contact::surface::{Aabb, SurfaceBody, quad_bounds};
use granbed_kernel::mesh::sphere::SphereMeshParams;

type Vec3 = [Real; 3];

/// Owned lists of one pass.
#[derive(Default)]
struct Lists {
    nodes: Vec<u32>,
    starts: Vec<u32>,
    faces: Vec<u32>,
    used: Vec<u32>,
}

impl Lists {
    fn view(&self) -> FaceLists<'_> {
        FaceLists {
            nodes: &self.nodes,
            starts: &self.starts,
            faces: &self.faces,
            used: &self.used,
        }
    }
}

fn build_lists(slave: &AnchorSurface<'_>, master: &AnchorSurface<'_>, d: Real) -> Lists {
    let mut l = Lists {
        nodes: vec![0; slave.x.len()],
        starts: vec![0; slave.x.len() + 1],
        faces: vec![0; 8],
        used: vec![0; master.quads.len()],
    };
    let mut scratch = vec![ReachBox::default(); master.quads.len()];
    let len = loop {
        let out = FaceListsMut {
            nodes: &mut l.nodes,
            starts: &mut l.starts,
            faces: &mut l.faces,
            used: &mut l.used,
        };
        match build(slave, master, 0.25, d, &mut scratch, out) {
            Ok(len) => break len,
            Err(_) => {
                let grown = 2 * l.faces.len();
                l.faces.resize(grown, 0);
            }
        }
    };
    l.nodes.truncate(len.nodes);
    l.starts.truncate(len.nodes + 1);
    l.faces.truncate(len.faces);
    l.used.truncate(len.used);
    l
}

struct Scene {
    mesh: common::OwnedMesh,
    first: usize,
    /// Anchor and predicted positions of bodies A and B (all nodes).
    anchor: [Vec<Vec3>; 2],
    pred: [Vec<Vec3>; 2],
}

/// Two granules (radius 0.5 mm, n = 4) pressed `overlap` into each other
/// along a random direction, each randomly rotated; the predicted
/// positions move every surface node by a random vector of length at most
/// `moved` from its anchor.
fn scene(seed: u64, overlap: Real, moved: Real) -> Scene {
    let mesh = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let first = mesh.size.nodes - mesh.size.surface_nodes;
    let mut rng = Rng::new(seed);
    let dir = {
        let v: Vec3 = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / n)
    };
    let gap = 1.0e-3 - overlap;
    let place = |rng: &mut Rng, centre: Vec3| -> Vec<Vec3> {
        let r = rng.rotation();
        mesh.positions
            .iter()
            .map(|p| {
                core::array::from_fn(|i| centre[i] + (0..3).map(|j| r[(i, j)] * p[j]).sum::<Real>())
            })
            .collect()
    };
    let anchor = [
        place(&mut rng, [0.0; 3]),
        place(&mut rng, dir.map(|c| c * gap)),
    ];
    let pred = anchor.clone().map(|x| {
        x.iter()
            .enumerate()
            .map(|(i, p)| {
                if i < first {
                    return *p;
                }
                let c = moved / (3.0 as Real).sqrt();
                core::array::from_fn(|k| p[k] + rng.uniform(-c, c))
            })
            .collect()
    });
    Scene {
        mesh,
        first,
        anchor,
        pred,
    }
}

/// A body on `x` (its own predicted and current positions).
fn surface<'a>(
    x: &'a [Vec3],
    first: usize,
    (quads, node_quads): (&'a [[u32; 4]], &'a [[u32; 4]]),
    boxes: &'a [Aabb],
    mass: &'a [Real],
) -> SurfaceBody<'a> {
    SurfaceBody {
        x_n: x,
        x_pred: x,
        mass,
        first_surface: first,
        quads,
        node_quads,
        bounds: Aabb::of_surface(x, first),
        sphere: bounding_sphere(x, first),
        quad_bounds: boxes,
    }
}

/// The box of every quad of `quads` on `x`.
fn boxes(x: &[Vec3], quads: &[[u32; 4]]) -> Vec<Aabb> {
    let mut b = vec![Aabb::EMPTY; quads.len()];
    quad_bounds(x, quads, &mut b);
    b
}

/// (full pass, listed pass) constraints of `a` against `b`, the lists
/// built on `anchors` (A's, B's) with drift `d`; checks that the listed
/// pass leaves its slot buffer clean.
fn full_and_listed(
    (a, b): (&SurfaceBody<'_>, &SurfaceBody<'_>),
    settings: &PairSettings,
    anchors: [AnchorSurface<'_>; 2],
    d: Real,
) -> (Vec<Constraint>, Vec<Constraint>) {
    let quads = a.quads.len().max(b.quads.len());
    let mut scratch = vec![CandidateFace::default(); quads];
    let mut full = vec![Constraint::default(); 4096];
    let n = detect(a, b, settings, &mut scratch, &mut full).unwrap();
    full.truncate(n);
    let ab = build_lists(&anchors[0], &anchors[1], d);
    let ba = build_lists(&anchors[1], &anchors[0], d);
    let mut slot = vec![u32::MAX; quads];
    let mut listed = vec![Constraint::default(); 4096];
    let n = detect_listed(
        a,
        b,
        settings,
        [&ab.view(), &ba.view()],
        &mut scratch,
        &mut slot,
        &mut listed,
    )
    .unwrap();
    listed.truncate(n);
    assert!(slot.iter().all(|&k| k == u32::MAX), "slot left clean");
    (full, listed)
}

/// (full pass, listed pass) constraints of scene `s`, lists built with
/// drift `d`.
fn both(s: &Scene, d: Real) -> (Vec<Constraint>, Vec<Constraint>) {
    both_with(s, d, PairSettings::standard(0.1))
}

/// [`both`] with `settings`.
fn both_with(s: &Scene, d: Real, settings: PairSettings) -> (Vec<Constraint>, Vec<Constraint>) {
    let mesh = (&s.mesh.quads[..], &s.mesh.node_quads[..]);
    let quad_boxes = s.pred.each_ref().map(|x| boxes(x, mesh.0));
    let mass = vec![1e-9; s.mesh.positions.len()];
    let a = surface(&s.pred[0], s.first, mesh, &quad_boxes[0], &mass);
    let b = surface(&s.pred[1], s.first, mesh, &quad_boxes[1], &mass);
    let anchors = s.anchor.each_ref().map(|x| AnchorSurface {
        x: &x[s.first..],
        first_surface: s.first,
        quads: mesh.0,
    });
    full_and_listed((&a, &b), &settings, anchors, d)
}

/// A drift or window fraction that is NaN, negative or infinite is
/// refused by name (with a NaN drift the lists came out empty and the
/// listed detection missed the contact without an error).
#[test]
fn build_refuses_a_drift_or_window_that_is_not_a_length() {
    use granbed_kernel::contact::pair::ContactError;
    let s = scene(3, 0.05e-3, 0.0);
    let anchors = s.anchor.each_ref().map(|x| AnchorSurface {
        x: &x[s.first..],
        first_surface: s.first,
        quads: &s.mesh.quads[..],
    });
    let n = anchors[0].x.len();
    let (mut nodes, mut starts) = (vec![0; n], vec![0; n + 1]);
    let (mut faces, mut used) = (vec![0; 1 << 16], vec![0; s.mesh.quads.len()]);
    let mut scratch = vec![ReachBox::default(); s.mesh.quads.len()];
    let mut run = |f: Real, d: Real| {
        let out = FaceListsMut {
            nodes: &mut nodes,
            starts: &mut starts,
            faces: &mut faces,
            used: &mut used,
        };
        build(&anchors[0], &anchors[1], f, d, &mut scratch, out)
    };
    let listed = run(0.25, 1e-6).unwrap();
    assert!(listed.faces > 0, "the overlapping pair lists faces");
    for (f, d, name) in [
        (0.25, Real::NAN, "drift"),
        (0.25, -1e-3, "drift"),
        (0.25, Real::INFINITY, "drift"),
        (Real::NAN, 1e-6, "window_fraction"),
        (-0.1, 1e-6, "window_fraction"),
    ] {
        match run(f, d) {
            Err(ContactError::InvalidParameter { field, .. }) => assert_eq!(field, name),
            other => panic!("f = {f}, drift = {d}: {other:?}"),
        }
    }
}

/// Bit patterns of a constraint list, so −0.0 ≠ 0.0 and NaN = NaN.
fn bits(c: &[Constraint]) -> Vec<(u8, u32, u32, Vec<u64>)> {
    c.iter()
        .map(|c| {
            let mut v: Vec<u64> = c.weights.iter().map(|w| w.to_bits()).collect();
            v.extend(c.normal.iter().map(|n| n.to_bits()));
            v.push(c.gap.to_bits());
            (c.side as u8, c.slave, c.quad, v)
        })
        .collect()
}

#[test]
fn listed_detection_finds_the_full_passes_constraints_while_nodes_stay_within_the_drift() {
    // Nodes moved up to 100 µm, more than the faces' windows (about 70 µm).
    let d = 100e-6;
    let mut constraints = 0;
    for seed in 0..40 {
        let overlap = 20e-6 + 2e-6 * seed as Real;
        let s = scene(seed, overlap, d);
        for body in 0..2 {
            let moved = drift(&s.pred[body], s.first, &s.anchor[body][s.first..]);
            assert!(moved <= d, "seed {seed}: moved {moved} > {d}");
        }
        let (full, listed) = both(&s, d);
        assert_eq!(bits(&full), bits(&listed), "seed {seed}");
        constraints += full.len();
    }
    assert!(
        constraints > 100,
        "the scenes touch: {constraints} constraints"
    );
}

/// With a capture distance the lists still give the full pass's
/// constraints, near ones (in front of a face, gap ≥ 0) included: a node
/// within the capture distance in front of a face lies in the face's box
/// grown by its window, which the lists cover.
#[test]
fn listed_detection_finds_the_near_constraints_of_a_capture_distance_too() {
    let d = 100e-6;
    let settings = PairSettings {
        capture: 10e-6,
        ..PairSettings::standard(0.1)
    };
    let (mut near, mut constraints) = (0, 0);
    for seed in 0..40 {
        let overlap = 20e-6 + 2e-6 * seed as Real;
        let s = scene(seed, overlap, d);
        let (full, listed) = both_with(&s, d, settings);
        assert_eq!(bits(&full), bits(&listed), "seed {seed}");
        near += full.iter().filter(|c| c.gap >= 0.0).count();
        constraints += full.len();
        // The penetrating ones are those of no capture, to the bit.
        let (plain, _) = both(&s, d);
        let mut kept = full.clone();
        let k = granbed_kernel::contact::pair::penetrating(&mut kept);
        assert_eq!(bits(&kept[..k]), bits(&plain), "seed {seed}");
    }
    assert!(
        near > 20 && near < constraints,
        "{near} near of {constraints} constraints"
    );
}

#[test]
fn lists_without_the_skin_miss_constraints_of_moved_nodes() {
    // The same scenes (nodes moved up to 100 µm), lists built as if nothing
    // would move: some node now reaches a face its list lacks, and the
    // listed pass differs.
    let differ = (0..40)
        .filter(|&seed| {
            let s = scene(seed, 20e-6 + 2e-6 * seed as Real, 100e-6);
            let (full, listed) = both(&s, 0.0);
            bits(&full) != bits(&listed)
        })
        .count();
    assert!(differ > 0, "no scene tells the skin is needed");
}

#[test]
fn drift_is_the_largest_surface_displacement_and_nan_for_bad_input() {
    let x = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 3.0, 4.0]];
    let anchor = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
    assert_eq!(drift(&x, 1, &anchor), 5.0);
    assert!(drift(&x, 2, &anchor).is_nan());
    assert!(drift(&x, 4, &anchor).is_nan());
    let nan = [[0.0; 3], [Real::NAN, 0.0, 0.0], [0.0; 3]];
    assert!(drift(&nan, 1, &anchor).is_nan());
}

/// The "nearer face" rule may let a small face overrule a deep hit on a
/// large one: the small face must be in the node's list although the
/// node is beyond its own window (lists grown by each face's own window
/// missed it, and the listed pass kept the far-side contact).
#[test]
fn a_small_face_that_overrules_a_hit_on_a_large_one_is_listed() {
    // Master: a small face 0 (diagonal 0.14, window 0.035) in z = 0 and,
    // not connected to it, a large face 1 (diagonal 1.28, window 0.32)
    // in z = 0.3, both facing +z. The slave quad (facing −z) lies 0.2
    // behind face 1 and 0.02–0.16 from face 0's box: face 0 is nearer
    // than the hit's depth, so there is no contact.
    let master: Vec<Vec3> = vec![
        [0.9, 0.45, 0.0],
        [1.0, 0.45, 0.0],
        [1.0, 0.55, 0.0],
        [0.9, 0.55, 0.0],
        [0.8, 0.0, 0.3],
        [1.6, 0.0, 0.3],
        [1.6, 1.0, 0.3],
        [0.8, 1.0, 0.3],
    ];
    let master_quads = [[0u32, 1, 2, 3], [4, 5, 6, 7]];
    let slave: Vec<Vec3> = vec![
        [1.02, 0.5, 0.1],
        [1.02, 0.6, 0.1],
        [1.12, 0.6, 0.1],
        [1.12, 0.5, 0.1],
    ];
    let slave_quads = [[0u32, 1, 2, 3]];
    let slave_node_quads = [[0u32, u32::MAX, u32::MAX, u32::MAX]; 4];
    let master_node_quads = vec![[u32::MAX; 4]; master.len()];
    let (slave_boxes, master_boxes) = (boxes(&slave, &slave_quads), boxes(&master, &master_quads));
    let mass = [1.0; 8];
    let a = surface(
        &slave,
        0,
        (&slave_quads, &slave_node_quads),
        &slave_boxes,
        &mass[..4],
    );
    let b = surface(
        &master,
        0,
        (&master_quads, &master_node_quads),
        &master_boxes,
        &mass,
    );
    let settings = PairSettings {
        margin: 0.5,
        symmetric: false,
        ..PairSettings::standard(0.0)
    };
    let anchors = [(&slave, &slave_quads[..]), (&master, &master_quads[..])].map(|(x, quads)| {
        AnchorSurface {
            x,
            first_surface: 0,
            quads,
        }
    });
    let (full, listed) = full_and_listed((&a, &b), &settings, anchors, 1e-3);
    assert!(full.is_empty(), "the full pass holds no node: {full:?}");
    assert!(listed.is_empty(), "the listed pass holds {listed:?}");
}

/// The lists are their definition (module docs): node p lists face q
/// exactly when q's anchor box grown by τ = (f·G + (2 + 2f)·d)(1 + 10⁻⁶)
/// holds p, G the master's largest face diagonal — checked against every
/// node × face of granules pressed together, side by side with a gap and
/// far apart, so that the prefilters of `build` (faces whose reach misses
/// the slave's box, nodes outside every remaining reach) leave out only
/// faces and nodes that list nothing.
#[test]
fn the_lists_are_every_face_whose_grown_box_holds_the_node() {
    let d = 30e-6;
    let mut listed = 0;
    for (seed, overlap) in [(1, 40e-6), (2, 0.0), (3, -60e-6), (4, -0.6e-3), (5, 25e-6)] {
        let s = scene(seed, overlap, 0.0);
        let surface = |b: usize| AnchorSurface {
            x: &s.anchor[b][s.first..],
            first_surface: s.first,
            quads: &s.mesh.quads,
        };
        for (slave, master) in [(surface(0), surface(1)), (surface(1), surface(0))] {
            let lists = build_lists(&slave, &master, d);
            let corners = |q: &[u32; 4]| q.map(|id| master.x[id as usize - s.first]);
            let largest = master
                .quads
                .iter()
                .map(|q| face_diagonal(&corners(q)))
                .fold(0.0, Real::max);
            let tau = (0.25 * largest + (2.0 + 2.0 * 0.25) * d) * (1.0 + 1e-6);
            let mut want = Lists::default();
            for (i, p) in slave.x.iter().enumerate() {
                let start = want.faces.len() as u32;
                for (q, quad) in master.quads.iter().enumerate() {
                    if Aabb::of_points(&corners(quad)).expanded(tau).contains(p) {
                        want.faces.push(q as u32);
                    }
                }
                if want.faces.len() as u32 > start {
                    want.nodes.push((s.first + i) as u32);
                    want.starts.push(start);
                }
            }
            want.starts.push(want.faces.len() as u32);
            want.used = want.faces.clone();
            want.used.sort_unstable();
            want.used.dedup();
            assert_eq!(lists.nodes, want.nodes, "seed {seed}: nodes");
            assert_eq!(lists.starts, want.starts, "seed {seed}: starts");
            assert_eq!(lists.faces, want.faces, "seed {seed}: faces");
            assert_eq!(lists.used, want.used, "seed {seed}: used");
            listed += lists.faces.len();
        }
    }
    assert!(listed > 100, "the scenes list faces: {listed}");
}
