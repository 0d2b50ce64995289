//! Contact with bad input: the kernel returns an error naming the field or
//! buffer (or, where the physics says so, no contact) — never a panic, a
//! pull, a NaN force or a silently wrong result.
//!
//! * `node_face_force`: a constraint with g ≥ 0 is inactive (zero force);
//!   a non-unit normal, NaN μ, Δt² = 0 or ∞, a zero master mass (even
//!   with weight 0), weights not summing to 1 are errors naming the field;
//! * `pair::forces` / `detect` / `detect_listed` / `mark_side`: ids outside
//!   the bodies are `IdOutOfRange` / `BufferLength` errors (or, for
//!   `mark_side`, which returns nothing, not counted);
//! * `wall_contact`: a NaN or infinite predicted position is no contact.

mod common;

use common::sphere_mesh;
use granbed_kernel::Real;
use granbed_kernel::contact::broad::bounding_sphere;
use granbed_kernel::contact::face_lists::FaceLists;
use granbed_kernel::contact::pair::{
    CandidateFace, Constraint, ContactError, Involvement, NodeFace, NodeForce, PairSettings, Side,
    detect, detect_listed, forces, mark_side, node_face_force,
};
use granbed_kernel::contact::rigid::RigidContact;
use granbed_kernel::contact::rigid::RigidShift;
use granbed_kernel::contact::surface::{Aabb, SurfaceBody, quad_bounds};
use granbed_kernel::contact::wall::{
    Plane, PredictedNodes, Wall, add_wall_contacts, count_wall_contacts, penetrates, plane_contact,
    wall_contact,
};
use granbed_kernel::granule::damping::RigidFrame;
use granbed_kernel::mesh::sphere::SphereMeshParams;

type Vec3 = [Real; 3];

/// A node 1 µm behind a flat face z = 0 of unit masses, moving 2 µm
/// sideways (so that μ = 0.3 slips).
fn penetrating() -> NodeFace {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    NodeFace {
        slave_mass: 1e-9,
        slave_x_n: [0.25, 0.25, 1e-6],
        slave_x_pred: [0.25 + 2e-6, 0.25, -1e-6],
        master_mass: [1e-9; 4],
        master_x_n: corners,
        master_x_pred: corners,
        weights: [0.5625, 0.1875, 0.0625, 0.1875],
        normal: [0.0, 0.0, 1.0],
        gap: -1e-6,
    }
}

/// The field an `InvalidParameter` error names (panics on anything else).
#[track_caller]
fn field<T: core::fmt::Debug>(r: Result<T, ContactError>) -> &'static str {
    match r {
        Err(e @ ContactError::InvalidParameter { field, .. }) => {
            assert!(e.to_string().contains(field), "{e}");
            field
        }
        other => panic!("expected an InvalidParameter error, got {other:?}"),
    }
}

#[test]
fn a_constraint_with_a_non_negative_gap_gives_no_force() {
    // Before: gap +1e-3 with μ = 0.3 gave F_n = −5000 N (a pull) and a
    // NaN slave force (the Coulomb cap went negative, 0/0).
    for gap in [1e-3, 1e-12, 0.0] {
        let c = NodeFace {
            gap,
            ..penetrating()
        };
        let f = node_face_force(&c, 1.0, 0.3, 1e-16).unwrap();
        assert_eq!(f.normal, 0.0, "gap {gap}");
        assert_eq!(f.force, [0.0; 3], "gap {gap}");
        assert_eq!(f.friction, [0.0; 3], "gap {gap}");
        assert!(!f.slipping);
    }
    // A penetrating constraint still pushes the slave out, friction capped.
    let f = node_face_force(&penetrating(), 1.0, 0.3, 1e-16).unwrap();
    assert!(f.normal > 0.0 && f.force[2] > 0.0 && f.slipping, "{f:?}");
    let ft = f.friction.iter().map(|v| v * v).sum::<Real>().sqrt();
    assert!((ft - 0.3 * f.normal).abs() <= 1e-12 * f.normal);
}

#[test]
fn node_face_force_rejects_bad_scalars_naming_the_field() {
    let c = penetrating();
    let with = |f: fn(&mut NodeFace)| {
        let mut c = penetrating();
        f(&mut c);
        c
    };
    assert_eq!(
        field(node_face_force(&c, 1.0, Real::NAN, 1e-16)),
        "friction"
    );
    assert_eq!(field(node_face_force(&c, 1.0, -0.1, 1e-16)), "friction");
    assert_eq!(field(node_face_force(&c, 1.0, 0.3, 0.0)), "dt_squared");
    assert_eq!(
        field(node_face_force(&c, 1.0, 0.3, Real::INFINITY)),
        "dt_squared"
    );
    assert_eq!(
        field(node_face_force(&c, 1.0, 0.3, Real::NAN)),
        "dt_squared"
    );
    assert_eq!(field(node_face_force(&c, 0.0, 0.3, 1e-16)), "weight");
    assert_eq!(field(node_face_force(&c, Real::NAN, 0.3, 1e-16)), "weight");
    // A zero master mass where the corner's weight is 0: 0/0 before.
    let c0 = NodeFace {
        weights: [1.0, 0.0, 0.0, 0.0],
        master_mass: [1e-9, 0.0, 1e-9, 1e-9],
        ..c
    };
    assert_eq!(field(node_face_force(&c0, 1.0, 0.3, 1e-16)), "master_mass");
    assert_eq!(
        field(node_face_force(
            &with(|c| c.slave_mass = -1e-9),
            1.0,
            0.3,
            1e-16
        )),
        "slave_mass"
    );
    for normal in [
        [0.0; 3],
        [0.0, 0.0, 1e6],
        [0.0, 0.0, 1.0 + 2e-6],
        [Real::NAN; 3],
    ] {
        let c = NodeFace { normal, ..c };
        assert_eq!(
            field(node_face_force(&c, 1.0, 0.3, 1e-16)),
            "normal",
            "{normal:?}"
        );
    }
    // Within the stated tolerance | |n| − 1 | ≤ 1e-6 a normal is accepted.
    let nearly = NodeFace {
        normal: [0.0, 0.0, 1.0 + 0.5e-6],
        ..c
    };
    assert!(node_face_force(&nearly, 1.0, 0.3, 1e-16).is_ok());
    let skew = NodeFace {
        weights: [0.5, 0.5, 0.5, 0.0],
        ..c
    };
    assert_eq!(field(node_face_force(&skew, 1.0, 0.3, 1e-16)), "weights");
    // Summing to 1 but off the face.
    let off = NodeFace {
        weights: [2.0, -1.0, 0.0, 0.0],
        ..c
    };
    assert_eq!(field(node_face_force(&off, 1.0, 0.3, 1e-16)), "weights");
    // Finite inputs whose force overflows: refused, not an infinite force.
    let huge = NodeFace { gap: -1e300, ..c };
    assert_eq!(field(node_face_force(&huge, 1.0, 0.3, 1e-300)), "gap");
    assert!(node_face_force(&huge, 1.0, 0.3, 1e-16).is_ok());
    assert_eq!(
        field(node_face_force(
            &with(|c| c.gap = Real::NAN),
            1.0,
            0.3,
            1e-16
        )),
        "gap"
    );
    assert_eq!(
        field(node_face_force(
            &with(|c| c.master_x_pred[2][1] = Real::INFINITY),
            1.0,
            0.3,
            1e-16
        )),
        "master_x_pred"
    );
}

/// A small sphere mesh as one body (x_n = x̃ = the mesh), unit-ish masses.
struct Body {
    x: Vec<Vec3>,
    mass: Vec<Real>,
    quads: Vec<[u32; 4]>,
    node_quads: Vec<[u32; 4]>,
    first: usize,
}

fn sphere(shift: Real) -> Body {
    let m = sphere_mesh(&SphereMeshParams::new(0.5e-3, 4, 1));
    let first = m.positions.len() - m.node_quads.len();
    Body {
        x: m.positions
            .iter()
            .map(|p| [p[0], p[1], p[2] + shift])
            .collect(),
        mass: vec![1e-9; m.positions.len()],
        quads: m.quads,
        node_quads: m.node_quads,
        first,
    }
}

/// A constraint of `b`'s first surface node against quad 0, 1 µm deep:
/// valid in every field.
fn penetrating_constraint(b: &Body) -> Constraint {
    Constraint {
        side: Side::A,
        slave: b.first as u32,
        quad: 0,
        weights: [0.25; 4],
        normal: [0.0, 0.0, 1.0],
        gap: -1e-6,
        watch: false,
    }
}

/// Calls `f` with the body's surface (its quad boxes computed here).
fn with_surface<R>(b: &Body, f: impl FnOnce(SurfaceBody<'_>) -> R) -> R {
    let mut boxes = vec![Aabb::EMPTY; b.quads.len()];
    quad_bounds(&b.x, &b.quads, &mut boxes);
    f(SurfaceBody {
        x_n: &b.x,
        x_pred: &b.x,
        mass: &b.mass,
        first_surface: b.first,
        quads: &b.quads,
        node_quads: &b.node_quads,
        bounds: Aabb::of_surface(&b.x, b.first),
        sphere: bounding_sphere(&b.x, b.first),
        quad_bounds: &boxes,
    })
}

/// `forces` of `constraints` between `a` and itself (the geometry does not
/// matter to the checks).
fn forces_on(
    a: &SurfaceBody<'_>,
    constraints: &[Constraint],
    settings: &PairSettings,
    dt_squared: Real,
) -> Result<(usize, granbed_kernel::contact::pair::PairForce), ContactError> {
    let mut out = vec![NodeForce::default(); 5 * constraints.len()];
    forces(
        (a, &[]),
        (a, &[]),
        constraints,
        settings,
        dt_squared,
        &mut out,
    )
}

#[track_caller]
fn out_of_range<T: core::fmt::Debug>(r: Result<T, ContactError>) -> (&'static str, u32) {
    match r {
        Err(
            e @ ContactError::IdOutOfRange {
                buffer, id, len, ..
            },
        ) => {
            assert!(id as usize >= len, "{e}");
            assert!(e.to_string().contains(buffer), "{e}");
            (buffer, id)
        }
        other => panic!("expected an IdOutOfRange error, got {other:?}"),
    }
}

#[test]
fn pair_forces_reject_bad_ids_buffers_and_scalars() {
    let b = sphere(0.0);
    let ok = penetrating_constraint(&b);
    let settings = PairSettings::standard(0.3);
    with_surface(&b, |a| {
        let (k, total) = forces_on(&a, &[ok], &settings, 1e-16).unwrap();
        assert_eq!((k, total.constraints), (5, 1));
        // Ids outside the bodies (before: index panics).
        let bad_quad = Constraint {
            quad: 999_999,
            ..ok
        };
        let r = forces_on(&a, &[ok, bad_quad], &settings, 1e-16);
        assert_eq!(out_of_range(r), ("constraints.quad", 999_999));
        let bad_slave = Constraint {
            slave: 999_999,
            ..ok
        };
        let r = forces_on(&a, &[bad_slave], &settings, 1e-16);
        assert_eq!(out_of_range(r), ("constraints.slave", 999_999));
        let mut quads = b.quads.clone();
        quads[0][2] = 777_777;
        let bad_corner = SurfaceBody { quads: &quads, ..a };
        let r = forces_on(&bad_corner, &[ok], &settings, 1e-16);
        assert_eq!(out_of_range(r), ("quads", 777_777));
        // A constraint on an interior node has no tributary area.
        let interior = Constraint { slave: 0, ..ok };
        let area = PairSettings {
            contact_area: true,
            ..settings
        };
        assert!(forces_on(&a, &[interior], &settings, 1e-16).is_ok());
        assert!(matches!(
            forces_on(&a, &[interior], &area, 1e-16),
            Err(ContactError::IdOutOfRange { .. })
        ));
        // A short mass buffer (before: index panic) or share slice.
        let short = SurfaceBody {
            mass: &b.mass[..3],
            ..a
        };
        let r = forces_on(&short, &[ok], &settings, 1e-16);
        assert!(
            matches!(
                r,
                Err(ContactError::BufferLength {
                    buffer: "mass",
                    got: 3,
                    ..
                })
            ),
            "{r:?}"
        );
        let mut out = vec![NodeForce::default(); 5];
        let r = forces(
            (&a, &[1u16; 3]),
            (&a, &[]),
            &[ok],
            &settings,
            1e-16,
            &mut out,
        );
        assert!(
            matches!(
                r,
                Err(ContactError::BufferLength {
                    buffer: "share_a",
                    ..
                })
            ),
            "{r:?}"
        );
        // Per-call scalars.
        assert_eq!(field(forces_on(&a, &[ok], &settings, 0.0)), "dt_squared");
        assert_eq!(
            field(forces_on(&a, &[ok], &settings, Real::NAN)),
            "dt_squared"
        );
        let negative = PairSettings::standard(-1.0);
        assert_eq!(field(forces_on(&a, &[ok], &negative, 1e-16)), "friction");
        let nan = PairSettings::standard(Real::NAN);
        assert_eq!(field(forces_on(&a, &[ok], &nan, 1e-16)), "friction");
        let nan_gap = Constraint {
            gap: Real::NAN,
            ..ok
        };
        assert_eq!(
            field(forces_on(&a, &[nan_gap], &settings, 1e-16)),
            "constraints.gap"
        );
        // A near constraint (g ≥ 0) is inactive: nothing written, no pull.
        let near = Constraint { gap: 1e-3, ..ok };
        let (k, total) = forces_on(&a, &[near], &settings, 1e-16).unwrap();
        assert_eq!((k, total.constraints, total.normal), (0, 0, 0.0));
        let (k, total) = forces_on(&a, &[near, ok], &settings, 1e-16).unwrap();
        assert_eq!((k, total.constraints), (5, 1));
        assert!(total.normal > 0.0 && total.total_on_a.iter().all(|v| v.is_finite()));
    });
}

#[test]
fn mark_side_skips_ids_outside_its_buffers() {
    let b = sphere(0.0);
    let n = b.x.len();
    let ok = penetrating_constraint(&b);
    let (mut tag, mut count) = (vec![u32::MAX; n], vec![0u16; n]);
    let constraints = [
        Constraint {
            side: Side::B,
            quad: 999_999,
            ..ok
        },
        Constraint {
            slave: 999_999,
            ..ok
        },
        Constraint { gap: 1e-6, ..ok },
        ok,
    ];
    let mut inv = Involvement {
        tag: &mut tag,
        count: &mut count,
    };
    // Before: an index panic on the quad id.
    mark_side(&constraints, Side::A, &b.quads, &mut inv, 1);
    assert_eq!(count.iter().map(|&c| u32::from(c)).sum::<u32>(), 1);
    assert_eq!(count[b.first], 1);
    // Involvement buffers shorter than the ids: not counted, no panic.
    let (mut tag, mut count) = (vec![u32::MAX; 2], vec![0u16; 2]);
    let mut inv = Involvement {
        tag: &mut tag,
        count: &mut count,
    };
    mark_side(&[ok], Side::A, &b.quads, &mut inv, 1);
    mark_side(&[ok], Side::B, &b.quads, &mut inv, 1);
    assert_eq!(count, [0, 0]);
}

#[test]
fn detect_reports_ids_outside_the_bodies() {
    let lower = sphere(0.0);
    // The upper sphere overlaps the lower by 0.1 mm.
    let upper = sphere(0.9e-3);
    let settings = PairSettings::standard(0.3);
    let mut scratch = vec![CandidateFace::default(); lower.quads.len()];
    let mut out = vec![Constraint::default(); 4096];
    let found = with_surface(&lower, |a| {
        with_surface(&upper, |b| {
            detect(&a, &b, &settings, &mut scratch, &mut out)
        })
    })
    .unwrap();
    assert!(found > 0);
    // node_quads shorter than the surface (before: index panic in the
    // slave normal).
    let short = Body {
        node_quads: lower.node_quads[..2].to_vec(),
        ..sphere(0.0)
    };
    let r = with_surface(&short, |a| {
        with_surface(&upper, |b| {
            detect(&a, &b, &settings, &mut scratch, &mut out)
        })
    });
    assert!(matches!(r, Err(ContactError::IdOutOfRange { .. })), "{r:?}");
    // A quad naming a node the body does not have: quad_bounds does not
    // panic, detect names the quad's buffer.
    let mut bad = sphere(0.0);
    bad.quads[0][1] = 999_999;
    let r = with_surface(&bad, |a| detect(&a, &a, &settings, &mut scratch, &mut out));
    assert_eq!(out_of_range(r), ("quads", 999_999));
    // node_quads naming a quad the body does not have.
    let mut bad = sphere(0.0);
    for q in &mut bad.node_quads {
        q[0] = 555_555;
    }
    let r = with_surface(&bad, |a| {
        with_surface(&upper, |b| {
            detect(&a, &b, &settings, &mut scratch, &mut out)
        })
    });
    assert_eq!(out_of_range(r), ("node_quads", 555_555));
}

#[test]
fn detect_listed_reports_list_ids_outside_the_bodies() {
    let b = sphere(0.0);
    let settings = PairSettings {
        symmetric: false,
        ..PairSettings::standard(0.3)
    };
    let mut scratch = vec![CandidateFace::default(); b.quads.len()];
    let mut slot = vec![u32::MAX; b.quads.len()];
    let mut out = vec![Constraint::default(); 4096];
    let first = b.first as u32;
    let mut run = |lists: &FaceLists<'_>| {
        with_surface(&b, |a| {
            detect_listed(
                &a,
                &a,
                &settings,
                [lists, lists],
                &mut scratch,
                &mut slot,
                &mut out,
            )
        })
    };
    let bad_used = FaceLists {
        nodes: &[first],
        starts: &[0, 1],
        faces: &[0],
        used: &[0, 888_888],
    };
    assert_eq!(out_of_range(run(&bad_used)), ("face lists (used)", 888_888));
    let bad_node = FaceLists {
        nodes: &[999_999],
        starts: &[0, 1],
        faces: &[0],
        used: &[0],
    };
    assert_eq!(
        out_of_range(run(&bad_node)),
        ("face lists (nodes)", 999_999)
    );
    // A face id outside the quads in a node's list is no candidate.
    let bad_face = FaceLists {
        nodes: &[first],
        starts: &[0, 1],
        faces: &[888_888],
        used: &[0],
    };
    assert_eq!(run(&bad_face), Ok(0));
    // Offsets that do not lay out the faces (they panicked in
    // `FaceLists::faces_of`): too few, decreasing, past the faces.
    let few = FaceLists {
        nodes: &[first, first + 1],
        starts: &[0, 1],
        faces: &[0],
        used: &[0],
    };
    assert!(
        matches!(
            run(&few),
            Err(ContactError::BufferLength {
                buffer: "face lists (starts)",
                expected: 3,
                got: 2
            })
        ),
        "{:?}",
        run(&few)
    );
    let decreasing = FaceLists {
        nodes: &[first, first + 1],
        starts: &[0, 1, 0],
        faces: &[0],
        used: &[0],
    };
    assert_eq!(
        field(run(&decreasing)),
        "face lists (starts): index of a decreasing offset"
    );
    let past = FaceLists {
        nodes: &[first],
        starts: &[0, 7],
        faces: &[0],
        used: &[0],
    };
    assert_eq!(short(run(&past)), ("face lists (faces)", 7, 1));
    // Used quads repeated, more of them than the master has quads (they
    // overran the scratch: an index panic, session 55's API review), or
    // descending: refused by index.
    let repeated: Vec<u32> = vec![0; b.quads.len() + 1];
    let overrun = FaceLists {
        nodes: &[first],
        starts: &[0, 1],
        faces: &[0],
        used: &repeated,
    };
    assert_eq!(
        field(run(&overrun)),
        "face lists (used): index of an id not above the one before"
    );
    let descending = FaceLists {
        nodes: &[first],
        starts: &[0, 1],
        faces: &[0],
        used: &[3, 2],
    };
    assert!(
        matches!(
            run(&descending),
            Err(ContactError::InvalidParameter { value, .. }) if value == 1.0
        ),
        "{:?}",
        run(&descending)
    );
    assert!(few.faces_of(5).is_empty() && past.faces_of(0).is_empty());
    assert_eq!(bad_face.faces_of(0), &[888_888]);
    assert!(slot.iter().all(|&s| s == u32::MAX), "slot restored");
}

/// Nodes of masses `mass` at `x` that the step has not moved (x̃ = x_n),
/// without a rigid shift.
fn resting<'a>(mass: &'a [Real], x: &'a [Vec3]) -> PredictedNodes<'a> {
    PredictedNodes {
        mass,
        x_n: x,
        x_pred: x,
        rigid_shift: RigidShift::NONE,
    }
}

#[test]
fn a_non_finite_position_is_no_wall_contact() {
    assert!(penetrates(-1e-9));
    for gap in [0.0, 1e-9, Real::NAN, Real::NEG_INFINITY] {
        assert!(!penetrates(gap), "{gap}");
    }
    // Node 0 penetrates the floor z = 0 by 1 µm and the die by 1 mm;
    // node 1 is NaN; nodes 2 and 3 are at infinity, with gap −∞ for the
    // floor and the die respectively (before: NaN and infinite forces,
    // counted as contacts).
    let x = vec![
        [2e-3, 0.0, -1e-6],
        [Real::NAN; 3],
        [0.0, 0.0, Real::NEG_INFINITY],
        [Real::NEG_INFINITY, 0.0, 0.0],
    ];
    let mass = [1e-9; 4];
    let body = resting(&mass, &x);
    let floor = Wall::Plane(Plane {
        normal: [0.0, 0.0, 1.0],
        offset: 0.0,
    });
    for wall in [floor, Wall::Die { radius: 1e-3 }] {
        let mut f_c = vec![[0.0; 3]; 4];
        let w = wall_contact(&wall, 0.3, 1e-16, 0..4, &body, &[], &mut f_c).unwrap();
        // The node at infinity reports its depth, −∞, but gets no force.
        assert!(
            w.normal.is_finite() && w.min_gap == Real::NEG_INFINITY,
            "{w:?}"
        );
        assert!(f_c[0].iter().all(|v| v.is_finite()) && f_c[0] != [0.0; 3]);
        assert_eq!(f_c[1..], [[0.0; 3]; 3]);
        let mut count = [0u16; 4];
        count_wall_contacts(&wall, 0..4, &x, &mut count).unwrap();
        // NaN does not count (a node at −∞ may: it gets no force).
        assert_eq!(count[..2], [1, 0]);
        assert_eq!(w.contacts, 1);
    }
    let mut f_c = vec![[0.0; 3]; 4];
    wall_contact(&floor, 0.3, 1e-16, 0..4, &body, &[], &mut f_c).unwrap();
    assert!(
        (f_c[0][2] - 1e-9 * 1e-6 / 1e-16).abs() < 1e-9,
        "{:?}",
        f_c[0]
    );
}

/// The buffer, needed and given lengths of a `BufferLength` error (panics
/// on anything else).
#[track_caller]
fn short<T: core::fmt::Debug>(r: Result<T, ContactError>) -> (&'static str, usize, usize) {
    match r {
        Err(ContactError::BufferLength {
            buffer,
            expected,
            got,
        }) => (buffer, expected, got),
        other => panic!("expected a BufferLength error, got {other:?}"),
    }
}

/// The wall passes check what they are given before any node is touched:
/// a node range longer than a buffer is a `BufferLength` naming it (it
/// panicked), Δt² = 0 or μ < 0, a plane normal that is not a unit vector
/// or a die of no radius an `InvalidParameter` (they gave infinite or
/// scaled forces), and nothing is written to `f_c` or the counts.
#[test]
fn wall_passes_reject_short_buffers_and_bad_walls() {
    // Two nodes, the first 1 µm below the floor z = 0.
    let x = vec![[0.0, 0.0, -1e-6], [0.0, 0.0, 1e-3]];
    let mass = [1e-9; 2];
    let body = resting(&mass, &x);
    let floor = Plane {
        normal: [0.0, 0.0, 1.0],
        offset: 0.0,
    };
    let wall = Wall::Plane(floor);
    let mut f_c = vec![[0.0; 3]; 2];
    assert_eq!(
        short(wall_contact(&wall, 0.1, 1e-16, 0..3, &body, &[], &mut f_c)),
        ("mass", 3, 2)
    );
    assert_eq!(
        short(wall_contact(&wall, 0.1, 1e-16, 0..2, &body, &[1], &mut f_c)),
        ("share", 2, 1)
    );
    let mut f_short = vec![[0.0; 3]; 1];
    assert_eq!(
        short(wall_contact(
            &wall,
            0.1,
            1e-16,
            0..2,
            &body,
            &[],
            &mut f_short
        )),
        ("f_c", 2, 1)
    );
    let mut count = [0u16; 1];
    assert_eq!(
        short(count_wall_contacts(&wall, 0..2, &x, &mut count)),
        ("count", 2, 1)
    );
    let mut system = RigidContact::new(RigidFrame::of(&mass, &x));
    assert_eq!(
        short(add_wall_contacts(&wall, 0.1, 0..5, &body, &[], &mut system)),
        ("mass", 5, 2)
    );
    assert_eq!(
        field(wall_contact(&wall, 0.1, 0.0, 0..2, &body, &[], &mut f_c)),
        "dt_squared"
    );
    assert_eq!(
        field(wall_contact(&wall, -0.1, 1e-16, 0..2, &body, &[], &mut f_c)),
        "friction"
    );
    assert_eq!(
        field(add_wall_contacts(
            &wall,
            Real::NAN,
            0..2,
            &body,
            &[],
            &mut system
        )),
        "friction"
    );
    let doubled = Plane {
        normal: [0.0, 0.0, 2.0],
        ..floor
    };
    assert_eq!(
        field(plane_contact(&doubled, 0.1, 1e-16, 0..2, &body, &mut f_c)),
        "plane normal length"
    );
    let nowhere = Plane {
        offset: Real::NAN,
        ..floor
    };
    assert_eq!(
        field(count_wall_contacts(
            &Wall::Plane(nowhere),
            0..2,
            &x,
            &mut [0; 2]
        )),
        "plane offset"
    );
    assert_eq!(
        field(wall_contact(
            &Wall::Die { radius: 0.0 },
            0.1,
            1e-16,
            0..2,
            &body,
            &[],
            &mut f_c
        )),
        "die radius"
    );
    assert_eq!(f_c, vec![[0.0; 3]; 2], "a refused pass wrote forces");
    // The same call with good input: the floor pushes node 0 back.
    let w = plane_contact(&floor, 0.1, 1e-16, 0..2, &body, &mut f_c).unwrap();
    assert_eq!(w.contacts, 1);
    assert!(
        (f_c[0][2] - 1e-9 * 1e-6 / 1e-16).abs() < 1e-9,
        "{:?}",
        f_c[0]
    );
    // An empty range needs no buffer.
    assert_eq!(
        wall_contact(&wall, 0.1, 1e-16, 5..5, &body, &[], &mut []).unwrap(),
        Default::default()
    );
}
