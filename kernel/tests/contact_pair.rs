//! Node-to-surface detection between two bodies (`contact::pair::detect`)
//! on hand-made surfaces: which face a node is held against; and the
//! re-measure of held constraints on a moved configuration
//! (`contact::pair::regap`).

use granbed_kernel::Real;
use granbed_kernel::contact::broad::bounding_sphere;
use granbed_kernel::contact::pair::{
    CandidateFace, Constraint, ContactError, NodeForce, PairSettings, detect, forces, penetrating,
    regap,
};
use granbed_kernel::contact::surface::{Aabb, SurfaceBody, quad_bounds};

type Vec3 = [Real; 3];

/// Calls `f` with `slave` (one quad, facing −z) as body A and `master`'s
/// quads as body B, unit masses, x_n = x̃.
fn with_bodies<R>(
    slave: &[Vec3],
    master: &[Vec3],
    master_quads: &[[u32; 4]],
    f: impl FnOnce(&SurfaceBody<'_>, &SurfaceBody<'_>) -> R,
) -> R {
    let slave_quads = [[0u32, 1, 2, 3]];
    let slave_node_quads = [[0u32, u32::MAX, u32::MAX, u32::MAX]; 4];
    let master_node_quads = vec![[u32::MAX; 4]; master.len()];
    let mut slave_boxes = [Aabb::EMPTY; 1];
    quad_bounds(slave, &slave_quads, &mut slave_boxes);
    let mut master_boxes = vec![Aabb::EMPTY; master_quads.len()];
    quad_bounds(master, master_quads, &mut master_boxes);
    let mass_s = [1.0; 4];
    let mass_m = vec![1.0; master.len()];
    let a = SurfaceBody {
        x_n: slave,
        x_pred: slave,
        mass: &mass_s,
        first_surface: 0,
        quads: &slave_quads,
        node_quads: &slave_node_quads,
        bounds: Aabb::of_surface(slave, 0),
        sphere: bounding_sphere(slave, 0),
        quad_bounds: &slave_boxes,
    };
    let b = SurfaceBody {
        x_n: master,
        x_pred: master,
        mass: &mass_m,
        first_surface: 0,
        quads: master_quads,
        node_quads: &master_node_quads,
        bounds: Aabb::of_surface(master, 0),
        sphere: bounding_sphere(master, 0),
        quad_bounds: &master_boxes,
    };
    f(&a, &b)
}

/// Detects `slave`'s nodes (one quad, facing −z) against `master`'s quads
/// (single pass, a margin that covers the unit-sized scene: the master's
/// faces must lie within it of the slave's box to be tried).
fn constraints(slave: &[Vec3], master: &[Vec3], master_quads: &[[u32; 4]]) -> Vec<Constraint> {
    constraints_capturing(slave, master, master_quads, 0.0)
}

/// [`regap`] of `held` with `slave` (one quad) against `master`, held
/// constraints never re-projected.
fn regapped(
    slave: &[Vec3],
    master: &[Vec3],
    master_quads: &[[u32; 4]],
    held: &[Constraint],
) -> Result<Vec<Constraint>, ContactError> {
    regapped_with(slave, master, master_quads, held, &settings(0.0))
}

/// [`regap`] of `held` with `slave` (one quad) against `master` and
/// `settings`.
fn regapped_with(
    slave: &[Vec3],
    master: &[Vec3],
    master_quads: &[[u32; 4]],
    held: &[Constraint],
    settings: &PairSettings,
) -> Result<Vec<Constraint>, ContactError> {
    with_bodies(slave, master, master_quads, |a, b| {
        let mut out = vec![Constraint::default(); held.len()];
        let n = regap(a, b, held, settings, &mut out)?;
        out.truncate(n);
        Ok(out)
    })
}

/// The tests' detection settings: single pass, a margin that covers the
/// unit-sized scenes, capture distance `capture`, no watches, held
/// constraints never re-projected.
fn settings(capture: Real) -> PairSettings {
    PairSettings {
        margin: 0.5,
        symmetric: false,
        capture,
        ..PairSettings::standard(0.0)
    }
}

/// A slave quad in the plane z = `z`, corner (x, 0.5), facing −z.
fn slave_at(x: Real, z: Real) -> [Vec3; 4] {
    [
        [x, 0.5, z],
        [x, 0.6, z],
        [x + 0.1, 0.6, z],
        [x + 0.1, 0.5, z],
    ]
}

/// A master surface folded over itself: face 0 in z = 0 over x ∈ [0, 1],
/// face 1 (not connected to it) in z = 0.3 over x ∈ [0.8, 1.6], both
/// facing +z.
fn folded_master() -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let x = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.8, 0.0, 0.3],
        [1.6, 0.0, 0.3],
        [1.6, 1.0, 0.3],
        [0.8, 1.0, 0.3],
    ];
    (x, vec![[0, 1, 2, 3], [4, 5, 6, 7]])
}

/// [`constraints`] with a capture distance.
fn constraints_capturing(
    slave: &[Vec3],
    master: &[Vec3],
    master_quads: &[[u32; 4]],
    capture: Real,
) -> Vec<Constraint> {
    detected(slave, master, master_quads, &settings(capture))
}

/// [`detect`] of `slave`'s nodes (one quad) against `master`'s quads with
/// `settings`.
fn detected(
    slave: &[Vec3],
    master: &[Vec3],
    master_quads: &[[u32; 4]],
    settings: &PairSettings,
) -> Vec<Constraint> {
    with_bodies(slave, master, master_quads, |a, b| {
        let mut scratch = vec![CandidateFace::default(); master_quads.len()];
        let mut out = vec![Constraint::default(); 16];
        let n = detect(a, b, settings, &mut scratch, &mut out).unwrap();
        out.truncate(n);
        out
    })
}

/// A capture distance adds near constraints (gap ≥ 0) for nodes in front
/// of a face by less than it, and nothing else: nodes farther in front get
/// none, and the constraints of penetrating nodes keep their bits.
/// `penetrating` keeps the penetrating ones in their order.
#[test]
fn a_capture_distance_holds_the_nodes_just_in_front_of_a_face() {
    let (master, quads) = folded_master();
    let front = slave_at(0.4, 0.02);
    assert!(constraints(&front, &master, &quads).is_empty());
    assert!(constraints_capturing(&front, &master, &quads, 0.01).is_empty());
    let near = constraints_capturing(&front, &master, &quads, 0.05);
    assert_eq!(near.len(), 4, "{near:?}");
    for (c, x) in near.iter().zip(&front) {
        assert_eq!(c.quad, 0);
        assert!((c.gap - 0.02).abs() < 1e-12, "gap {}", c.gap);
        // The contact point is the node's foot on the face.
        let foot = [x[0], x[1]];
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        for a in 0..2 {
            let at: Real = c.weights.iter().zip(&corners).map(|(w, p)| w * p[a]).sum();
            assert!((at - foot[a]).abs() < 1e-12, "{c:?}");
        }
    }
    let behind = slave_at(0.4, -0.01);
    let plain = constraints(&behind, &master, &quads);
    assert_eq!(plain.len(), 4);
    assert_eq!(constraints_capturing(&behind, &master, &quads, 0.05), plain);
    // A slave quad tilted through the face: two nodes behind, two in front.
    let mut tilted = slave_at(0.4, -0.01);
    tilted[1][2] = 0.02;
    tilted[2][2] = 0.02;
    let mut mixed = constraints_capturing(&tilted, &master, &quads, 0.05);
    assert_eq!(mixed.len(), 4, "{mixed:?}");
    let k = penetrating(&mut mixed);
    assert_eq!(k, 2);
    assert_eq!(
        mixed[..k].iter().map(|c| c.slave).collect::<Vec<_>>(),
        [0, 3]
    );
    assert!(mixed[..k].iter().all(|c| c.gap < 0.0));
    assert_eq!(&mixed[..k], &constraints(&tilted, &master, &quads)[..]);
}

#[test]
fn a_node_beside_a_near_face_is_not_held_against_a_far_side_face() {
    let (master, quads) = folded_master();
    // Just beyond face 0's edge, 5 µm-scale below its plane: 0.02 from
    // face 0, but "inside" face 1, 0.305 behind it (within its window of
    // 0.25 × diagonal = 0.32). The nearest surface is face 0's edge, which
    // the node is beside, not behind: no contact.
    let slave = slave_at(1.02, -0.005);
    let found = constraints(&slave, &master, &quads);
    assert!(found.is_empty(), "far-side contacts: {found:?}");
    // Without the normal test (`nearest_penetrated_face`) the nearest
    // surface still decides, for the node's normal either way.
    let nearest = PairSettings {
        nearest_penetrated_face: true,
        ..settings(0.0)
    };
    let mut turned = slave;
    turned.reverse();
    for s in [slave, turned] {
        let found = detected(&s, &master, &quads, &nearest);
        assert!(found.is_empty(), "far-side contacts: {found:?}");
    }
}

#[test]
fn a_node_behind_a_face_far_from_other_faces_is_held_against_it() {
    let (master, quads) = folded_master();
    // 0.01 behind face 1, well away from face 0 (0.29 below is face 0's
    // plane, but its edge is 0.3 away): a contact with face 1.
    let slave = slave_at(1.4, 0.29);
    let found = constraints(&slave, &master, &quads);
    assert_eq!(found.len(), 4, "{found:?}");
    for c in &found {
        assert_eq!(c.quad, 1);
        assert!((c.gap + 0.01).abs() < 1e-12, "gap {}", c.gap);
    }
}

/// A node just below the bottom of a valley (two faces meeting at a
/// concave edge, both facing up) projects just off each face: no face
/// holds it, and the concave-edge search holds it against the shared edge
/// with the faces' averaged normal (+z) and its depth below the edge.
#[test]
fn a_node_below_a_concave_edge_is_held_against_the_edge() {
    let master = vec![
        [0.0, 0.0, 0.2],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.2],
        [2.0, 0.0, 0.2],
        [2.0, 1.0, 0.2],
    ];
    let quads = [[0, 1, 2, 3], [1, 4, 5, 2]];
    // Two nodes 0.005 below the edge x = 1, z = 0; the other two above
    // face 1 (z = 0.1 where it is at 0.06).
    let slave = [
        [1.0, 0.5, -0.005],
        [1.0, 0.6, -0.005],
        [1.3, 0.6, 0.1],
        [1.3, 0.5, 0.1],
    ];
    let found = constraints(&slave, &master, &quads);
    assert_eq!(found.len(), 2, "{found:?}");
    for c in &found {
        assert!(c.slave < 2, "{c:?}");
        assert!((c.gap + 0.005).abs() < 1e-12, "gap {}", c.gap);
        assert!((c.normal[2] - 1.0).abs() < 1e-12, "normal {:?}", c.normal);
    }
}

/// On a flat face the gap along the held normal is exact for any motion of
/// the node: regap agrees with a new search wherever the node still
/// penetrates (sliding along the face included), drops the nodes that
/// moved out, keeps the held order, and on the unmoved configuration
/// returns the held constraints (gaps up to round-off).
#[test]
fn held_constraints_are_re_measured_on_the_moved_configuration() {
    let (master, quads) = folded_master();
    let slave = slave_at(1.3, 0.29);
    let held = constraints(&slave, &master, &quads);
    assert_eq!(held.len(), 4, "{held:?}");
    let same = regapped(&slave, &master, &quads, &held).unwrap();
    assert_eq!(same.len(), held.len());
    for (r, h) in same.iter().zip(&held) {
        // The same gap up to round-off (Σ Nᵢxᵢ against the projection's
        // own evaluation of the face).
        assert_eq!(Constraint { gap: h.gap, ..*r }, *h);
        assert!((r.gap - h.gap).abs() < 1e-15, "{} vs {}", r.gap, h.gap);
    }

    // Nodes 0 and 1 slide 0.05 along x and rise to 0.004 behind face 1;
    // nodes 2 and 3 rise 0.002 above it.
    let mut moved = slave;
    for (k, x) in moved.iter_mut().enumerate() {
        if k < 2 {
            x[0] += 0.05;
            x[2] = 0.296;
        } else {
            x[2] = 0.302;
        }
    }
    let again = regapped(&moved, &master, &quads, &held).unwrap();
    let fresh = constraints(&moved, &master, &quads);
    assert_eq!(again.len(), 2, "{again:?}");
    assert_eq!(fresh.len(), 2, "{fresh:?}");
    for (r, f) in again.iter().zip(&fresh) {
        assert_eq!((r.slave, r.quad), (f.slave, f.quad));
        assert!((r.gap - f.gap).abs() < 1e-12, "{} vs {}", r.gap, f.gap);
        assert!((r.gap + 0.004).abs() < 1e-12, "gap {}", r.gap);
    }
    // The held weights and normal, not the new contact point's.
    assert_eq!(again[0].weights, held[0].weights);
    assert_eq!(again[1].normal, held[1].normal);
}

/// A held constraint that does not fit the bodies (an id beyond their
/// nodes or quads) is an `IdOutOfRange` naming where the id was read, on
/// every path that measures it (the held measure, a watch, a re-projection
/// after a slide); an output shorter than the held list is a
/// `BufferLength`. Errors, not panics.
#[test]
fn a_held_constraint_of_other_bodies_is_an_error() {
    let (master, quads) = folded_master();
    let slave = slave_at(1.3, 0.29);
    let held = constraints(&slave, &master, &quads);
    // The buffer and id an `IdOutOfRange` error names (None: another
    // outcome).
    let out_of_range = |r: Result<Vec<Constraint>, ContactError>| match r {
        Err(ContactError::IdOutOfRange { buffer, id, .. }) => Some((buffer, id)),
        _ => None,
    };
    let mut bad = held.clone();
    bad[1].quad = 7;
    let r = regapped(&slave, &master, &quads, &bad);
    assert_eq!(out_of_range(r), Some(("held.quad", 7)));
    bad[1] = Constraint {
        slave: 9,
        ..held[1]
    };
    let r = regapped(&slave, &master, &quads, &bad);
    assert_eq!(out_of_range(r), Some(("held.slave", 9)));
    // A corner of the held face beyond the master's nodes, measured as
    // held, as a watch and as a slid constraint re-projected.
    let mut broken = quads.clone();
    broken[1][3] = 99;
    assert_eq!(
        out_of_range(regapped(&slave, &master, &broken, &held)),
        Some(("quads", 99))
    );
    let watched: Vec<Constraint> = held
        .iter()
        .map(|c| Constraint { watch: true, ..*c })
        .collect();
    let watching = PairSettings {
        watch_beside: true,
        ..settings(0.05)
    };
    assert_eq!(
        out_of_range(regapped_with(&slave, &master, &broken, &watched, &watching)),
        Some(("quads", 99))
    );
    let reprojecting = PairSettings {
        reproject_slide: 0.0,
        ..settings(0.0)
    };
    assert_eq!(
        out_of_range(regapped_with(
            &slave,
            &master,
            &broken,
            &held,
            &reprojecting
        )),
        Some(("quads", 99))
    );
    let r = with_bodies(&slave, &master, &quads, |a, b| {
        regap(a, b, &held, &settings(0.0), &mut [Constraint::default(); 2])
    });
    assert!(
        matches!(
            r,
            Err(ContactError::BufferLength {
                buffer: "constraints",
                ..
            })
        ),
        "{r:?}"
    );
}

/// `r`, written by `regap`, is the ordinary constraint `f` a search finds
/// on the same configuration: the same node and face, and weights, normal
/// and gap to round-off.
fn assert_found_as_a_search_finds(r: &Constraint, f: &Constraint) {
    assert_eq!((r.slave, r.quad, r.watch), (f.slave, f.quad, false));
    assert!((r.gap - f.gap).abs() < 1e-12, "{} vs {}", r.gap, f.gap);
    let close = |a: &[Real], b: &[Real]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    assert!(close(&r.weights, &f.weights), "{r:?} vs {f:?}");
    assert!(close(&r.normal, &f.normal), "{r:?} vs {f:?}");
}

/// One face over the unit square, facing +z, its corner (1, 1) lifted to
/// z = `lift` (the others at z = 0): flat for 0, else twisted.
fn unit_face(lift: Real) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let x = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, lift],
        [0.0, 1.0, 0.0],
    ];
    (x, vec![[0, 1, 2, 3]])
}

/// One flat face: z = 0 over the unit square, facing +z.
fn flat_master() -> (Vec<Vec3>, Vec<[u32; 4]>) {
    unit_face(0.0)
}

/// A node in front of a face's plane but just off the face (coming over its
/// edge) gets a watch, with a capture distance and `watch_beside`: `regap`
/// writes nothing for it while it stays off the face (even behind the
/// plane's extension) and, once it has crossed the face, the constraint a
/// new search finds. Without watches nothing is held for it, so the
/// crossing goes unseen until the next search.
#[test]
fn a_node_coming_over_a_faces_edge_is_watched_and_held_once_it_crosses() {
    let (master, quads) = flat_master();
    let watching = PairSettings {
        watch_beside: true,
        ..settings(0.05)
    };
    // Nodes 0 and 1 at x = 1.05 (ξ = 1.1, just beyond the edge x = 1),
    // nodes 2 and 3 at x = 1.15 (ξ = 1.3, beyond the reach of 0.25), all
    // 0.01 in front of the plane.
    let beside = slave_at(1.05, 0.01);
    assert!(constraints_capturing(&beside, &master, &quads, 0.05).is_empty());
    let held = detected(&beside, &master, &quads, &watching);
    assert_eq!(
        held.iter()
            .map(|c| (c.slave, c.quad, c.watch))
            .collect::<Vec<_>>(),
        [(0, 0, true), (1, 0, true)],
        "{held:?}"
    );
    assert!(
        held.iter().all(|c| (c.gap - 0.01).abs() < 1e-12),
        "{held:?}"
    );
    // No capture distance, no watches.
    let uncaptured = PairSettings {
        watch_beside: true,
        ..settings(0.0)
    };
    assert!(detected(&beside, &master, &quads, &uncaptured).is_empty());
    // Not contacts: what the forces take of them is nothing.
    assert_eq!(penetrating(&mut held.clone()), 0);
    // Behind the plane's extension but off the face: no constraint.
    let behind_extension = slave_at(1.05, -0.004);
    let none = regapped_with(&behind_extension, &master, &quads, &held, &watching).unwrap();
    assert!(none.is_empty(), "{none:?}");
    // Slid over the edge onto the face, 0.004 behind it: the search's
    // constraints (nodes 2 and 3, still off the face, have none).
    let crossed = slave_at(0.93, -0.004);
    let found = regapped_with(&crossed, &master, &quads, &held, &watching).unwrap();
    let fresh = constraints(&crossed, &master, &quads);
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!(fresh.len(), 2, "{fresh:?}");
    for (r, f) in found.iter().zip(&fresh) {
        assert!((r.gap + 0.004).abs() < 1e-12, "gap {}", r.gap);
        assert_found_as_a_search_finds(r, f);
    }
    // Re-measured with watches switched off (a run resumed so): dropped.
    let off = regapped_with(&crossed, &master, &quads, &held, &settings(0.05)).unwrap();
    assert!(off.is_empty(), "{off:?}");
}

/// Two faces facing +z, not connected: face 0 in z = `z0` over x ∈ [`x0`,
/// `x0` + 1], face 1 in z = `z1` over x ∈ [`x1`, `x1` + 1], both over
/// y ∈ [0, 1].
fn two_faces(x0: Real, z0: Real, x1: Real, z1: Real) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let face = |x: Real, z: Real| {
        [
            [x, 0.0, z],
            [x + 1.0, 0.0, z],
            [x + 1.0, 1.0, z],
            [x, 1.0, z],
        ]
    };
    let mut nodes = face(x0, z0).to_vec();
    nodes.extend(face(x1, z1));
    (nodes, vec![[0, 1, 2, 3], [4, 5, 6, 7]])
}

/// One held constraint per node, in this order of precedence: a near
/// constraint (in front of a face and on it) wins over a watch (in front of
/// a face and just beside it), even a watch on a nearer face; among the
/// faces a node lies just beside, the nearest gets the watch, wherever it
/// stands in the face list.
#[test]
fn a_near_constraint_wins_over_a_watch_and_the_nearest_face_is_watched() {
    let watching = PairSettings {
        watch_beside: true,
        ..settings(0.05)
    };
    let held_on = |master: &[Vec3], quads: &[[u32; 4]], slave: &[Vec3]| {
        detected(slave, master, quads, &watching)
            .iter()
            .map(|c| (c.slave, c.quad, c.watch))
            .collect::<Vec<_>>()
    };
    // Nodes 0 and 1 at x = 1.05, z = 0.01: just beside face 0 (z = 0, x
    // up to 1) 0.01 in front of its plane, and on face 1 (z = −0.02, x
    // from 1.0) 0.03 in front of it. Nodes 2 and 3 at x = 1.15 are beyond
    // face 0's reach and on face 1.
    let slave = slave_at(1.05, 0.01);
    let (master, quads) = two_faces(0.0, 0.0, 1.0, -0.02);
    let held = detected(&slave, &master, &quads, &watching);
    assert_eq!(
        held.iter()
            .map(|c| (c.slave, c.quad, c.watch))
            .collect::<Vec<_>>(),
        [(0, 1, false), (1, 1, false), (2, 1, false), (3, 1, false)],
        "{held:?}"
    );
    assert!(
        held.iter().all(|c| (c.gap - 0.03).abs() < 1e-12),
        "{held:?}"
    );
    // Both faces beside nodes 0 and 1 (x up to 1): the nearer, face 1 at
    // z = 0 (0.01 in front), is watched, not face 0 at z = −0.02 (0.03),
    // listed first; and so with the list the other way round.
    let (master, quads) = two_faces(0.0, -0.02, 0.0, 0.0);
    assert_eq!(
        held_on(&master, &quads, &slave),
        [(0, 1, true), (1, 1, true)]
    );
    let (master, quads) = two_faces(0.0, 0.0, 0.0, -0.02);
    assert_eq!(
        held_on(&master, &quads, &slave),
        [(0, 0, true), (1, 0, true)]
    );
}

/// A node inside a face and behind it, with no other face near, whose own
/// averaged normal does not oppose the face (the slave quad faces +z, as
/// the face does: a fold of a strongly compressed granule): physics.md's
/// normal test holds nothing against it; `nearest_penetrated_face` holds
/// it as any penetrating node, in a search and in a held constraint's
/// re-projection after a slide.
#[test]
fn a_node_whose_normal_turned_away_is_held_against_the_face_it_is_behind() {
    let (master, quads) = flat_master();
    // slave_at's corners in the other order: its normal is +z.
    let turned = |x: Real, z: Real| {
        let mut q = slave_at(x, z);
        q.reverse();
        q
    };
    let behind = turned(0.3, -0.004);
    assert!(constraints(&behind, &master, &quads).is_empty());
    let nearest = PairSettings {
        nearest_penetrated_face: true,
        ..settings(0.0)
    };
    let held = detected(&behind, &master, &quads, &nearest);
    assert_eq!(held.len(), 4, "{held:?}");
    assert!(
        held.iter()
            .all(|c| c.quad == 0 && (c.gap + 0.004).abs() < 1e-12),
        "{held:?}"
    );
    // The same nodes slid along the face, 0.006 behind it: re-projected,
    // they are kept with the new gap; under the normal test, dropped.
    let slid = turned(0.5, -0.006);
    let reproject = |nearest_penetrated_face| PairSettings {
        reproject_slide: 0.0,
        nearest_penetrated_face,
        ..settings(0.0)
    };
    let kept = regapped_with(&slid, &master, &quads, &held, &reproject(true)).unwrap();
    assert_eq!(kept.len(), 4, "{kept:?}");
    assert!(
        kept.iter().all(|c| (c.gap + 0.006).abs() < 1e-12),
        "{kept:?}"
    );
    let dropped = regapped_with(&slid, &master, &quads, &held, &reproject(false)).unwrap();
    assert!(dropped.is_empty(), "{dropped:?}");
}

/// A twisted face z = 0.4 x y over the unit square (a bilinear patch: its
/// normal (−0.4y, −0.4x, 1) turns across it), facing +z.
fn twisted_master() -> (Vec<Vec3>, Vec<[u32; 4]>) {
    unit_face(0.4)
}

/// A slave quad (facing down) over (c, c)–(c + 0.1, c + 0.1), each node
/// `depth` below the twisted face.
fn slave_under_twist(c: Real, depth: Real) -> [Vec3; 4] {
    [(c, c), (c, c + 0.1), (c + 0.1, c + 0.1), (c + 0.1, c)]
        .map(|(x, y)| [x, y, 0.4 * x * y - depth])
}

/// On a curved face the gap along the held normal misses how the face bends
/// under a node that slides along it: slid from (0.2, 0.2) to (0.6, 0.6)
/// and 0.002 behind the twisted face, the nodes measure clear of it at the
/// held contact points, and are dropped. With `reproject_slide` below the
/// slide they are projected afresh and held as a new search holds them;
/// with it above, and for a node slid off its face, the held measure stays.
#[test]
fn a_held_contact_slid_along_a_curved_face_is_projected_afresh() {
    let (master, quads) = twisted_master();
    let held = constraints(&slave_under_twist(0.2, 0.001), &master, &quads);
    assert_eq!(held.len(), 4, "{held:?}");
    let moved = slave_under_twist(0.6, 0.002);
    let fresh = constraints(&moved, &master, &quads);
    assert_eq!(fresh.len(), 4, "{fresh:?}");
    let first_order = regapped(&moved, &master, &quads, &held).unwrap();
    assert!(first_order.is_empty(), "{first_order:?}");
    let reproject = |slide| PairSettings {
        reproject_slide: slide,
        ..settings(0.0)
    };
    let again = regapped_with(&moved, &master, &quads, &held, &reproject(0.05)).unwrap();
    assert_eq!(again.len(), 4, "{again:?}");
    for (r, f) in again.iter().zip(&fresh) {
        assert_found_as_a_search_finds(r, f);
    }
    // A slide shorter than the setting: the held measure.
    let short = regapped_with(&moved, &master, &quads, &held, &reproject(10.0)).unwrap();
    assert!(short.is_empty(), "{short:?}");

    // Off the face (flat face 1 of the folded master ends at x = 1.6):
    // the held weights and normal, as without re-projection.
    let (master, quads) = folded_master();
    let slave = slave_at(1.3, 0.29);
    let held = constraints(&slave, &master, &quads);
    let off = slave_at(1.55, 0.296);
    let plain = regapped(&off, &master, &quads, &held).unwrap();
    assert_eq!(plain.len(), 4, "{plain:?}");
    assert_eq!(
        regapped_with(&off, &master, &quads, &held, &reproject(0.05)).unwrap()[2..],
        plain[2..]
    );
}

/// The contact area is estimated only when asked for: a slave quad of
/// 0.1 × 0.1 wholly behind a face (single pass, weight 1) has the area of
/// the quad, its four nodes' quarter shares; without it the area is 0 and
/// the forces are the same bits.
#[test]
fn the_contact_area_is_the_slave_nodes_tributary_area_when_asked_for() {
    let (master, quads) = folded_master();
    let slave = slave_at(1.3, 0.29);
    let held = constraints(&slave, &master, &quads);
    assert_eq!(held.len(), 4);
    let run = |contact_area| {
        with_bodies(&slave, &master, &quads, |a, b| {
            let settings = PairSettings {
                symmetric: false,
                contact_area,
                ..PairSettings::standard(0.1)
            };
            let mut out = vec![NodeForce::default(); 5 * held.len()];
            let (k, total) = forces((a, &[]), (b, &[]), &held, &settings, 1e-8, &mut out).unwrap();
            out.truncate(k);
            (out, total)
        })
    };
    let ((with, t_with), (without, t_without)) = (run(true), run(false));
    assert!((t_with.area - 0.01).abs() < 1e-15, "area {}", t_with.area);
    assert_eq!(t_without.area, 0.0);
    assert_eq!(with, without);
    assert_eq!(t_with.normal, t_without.normal);
    assert!(t_with.normal > 0.0);
}
