//! The hex cube of the friction oracle (physics.md §5.6 item 5): counts,
//! volume a³ and area 6a², outward quads, node–quad lists, surface nodes
//! last, and errors instead of panics on bad input.

mod common;

use common::assert_close;
use granbed_kernel::Real;
use granbed_kernel::element::reference::hex_reference;
use granbed_kernel::mesh::cube::{cube_size, generate_cube};
use granbed_kernel::mesh::sphere::{MeshBuffers, MeshError, MeshSize};
use granbed_kernel::mesh::surface::{area_and_volume, quad_area_and_flux};

const A: Real = 0.5e-3;

struct Cube {
    size: MeshSize,
    positions: Vec<[Real; 3]>,
    hexes: Vec<[u32; 8]>,
    quads: Vec<[u32; 4]>,
    node_quads: Vec<[u32; 4]>,
}

fn cube(side: Real, n: u32) -> Cube {
    let size = cube_size(n).expect("valid n");
    let mut c = Cube {
        size,
        positions: vec![[Real::NAN; 3]; size.nodes],
        hexes: vec![[u32::MAX; 8]; size.hexes],
        quads: vec![[u32::MAX; 4]; size.quads],
        node_quads: vec![[0; 4]; size.surface_nodes],
    };
    let mut scratch = vec![0; size.scratch];
    let written = generate_cube(
        side,
        n,
        &mut MeshBuffers {
            positions: &mut c.positions,
            hexes: &mut c.hexes,
            quads: &mut c.quads,
            node_quads: &mut c.node_quads,
            scratch: &mut scratch,
        },
    )
    .expect("cube generates");
    assert_eq!(written, size);
    c
}

fn sub(a: [Real; 3], b: [Real; 3]) -> [Real; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [Real; 3], b: [Real; 3]) -> [Real; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [Real; 3], b: [Real; 3]) -> Real {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

const LEVELS: [u32; 5] = [1, 2, 3, 4, 7];

#[test]
fn counts() {
    for n in LEVELS {
        let s = cube_size(n).unwrap();
        let n = n as usize;
        assert_eq!(s.nodes, (n + 1).pow(3), "nodes, n = {n}");
        assert_eq!(s.hexes, n.pow(3), "hexes, n = {n}");
        assert_eq!(s.quads, 6 * n * n, "quads, n = {n}");
        assert_eq!(s.surface_nodes, 6 * n * n + 2, "surface nodes, n = {n}");
        // The surface of the lattice: all points minus the (n−1)³ inside.
        assert_eq!(
            s.nodes - s.surface_nodes,
            (n - 1).pow(3),
            "interior, n = {n}"
        );
    }
    let c = cube(A, 4);
    assert_eq!((c.size.nodes, c.size.hexes, c.size.quads), (125, 64, 96));
}

/// Every hex has positive Gauss-point Jacobians (`hex_reference`), they sum
/// to a³, each is (a/n)³ and its nodes sit at the signed corners of hex8
/// order; the quads enclose a³ with area 6a².
#[test]
fn volume_area_and_element_order() {
    for n in LEVELS {
        let c = cube(A, n);
        let h = A / n as Real;
        let mut volume = 0.0;
        for (e, hex) in c.hexes.iter().enumerate() {
            let x: [[Real; 3]; 8] = core::array::from_fn(|i| c.positions[hex[i] as usize]);
            let r = hex_reference(&x).unwrap_or_else(|| panic!("hex {e} inverted (n = {n})"));
            assert_close("element volume", r.volume, h * h * h, 1e-12, 0.0);
            volume += r.volume;
            // Node I sits at the corner NODE_SIGNS[I] of the element.
            let centre: [Real; 3] =
                core::array::from_fn(|a| x.iter().map(|p| p[a]).sum::<Real>() / 8.0);
            for (i, p) in x.iter().enumerate() {
                let sg = granbed_kernel::element::hex8::NODE_SIGNS[i];
                for a in 0..3 {
                    assert_close("corner", p[a] - centre[a], 0.5 * h * sg[a], 1e-12, 0.0);
                }
            }
        }
        assert_close("sum V0", volume, A * A * A, 1e-12, 0.0);
        let (area, div_volume) = area_and_volume(&c.positions, &c.quads).unwrap();
        assert_close("surface area", area, 6.0 * A * A, 1e-12, 0.0);
        assert_close("divergence volume", div_volume, A * A * A, 1e-12, 0.0);
        for x in &c.positions {
            for &v in x {
                assert!(v.abs() <= 0.5 * A * (1.0 + 1e-15), "node outside: {x:?}");
            }
        }
    }
}

/// Each quad is a face cell of side a/n on a face of the cube, its
/// right-hand normal (x1 − x0) × (x3 − x0) is the outward face normal, and
/// its own flux ⅓∫x·n dA is positive.
#[test]
fn quads_point_outward() {
    for n in LEVELS {
        let c = cube(A, n);
        let h = A / n as Real;
        let mut per_face = [0usize; 6];
        for (f, q) in c.quads.iter().enumerate() {
            let x: [[Real; 3]; 4] = core::array::from_fn(|i| c.positions[q[i] as usize]);
            let normal = cross(sub(x[1], x[0]), sub(x[3], x[0]));
            // The face: the axis on which all four nodes sit at ±a/2.
            let axis = (0..3)
                .find(|&a| x.iter().all(|p| (p[a] - x[0][a]).abs() < 1e-15))
                .unwrap_or_else(|| panic!("quad {f} is not axis-aligned"));
            let outward = x[0][axis].signum();
            assert_close("face position", x[0][axis].abs(), 0.5 * A, 1e-12, 0.0);
            let mut expected = [0.0; 3];
            expected[axis] = outward * h * h;
            for a in 0..3 {
                assert_close("quad normal", normal[a], expected[a], 1e-12, 1e-24);
            }
            // The other diagonal corner agrees (a planar, convex, CCW quad).
            let n2 = cross(sub(x[3], x[2]), sub(x[1], x[2]));
            assert!(dot(n2, expected) > 0.0, "quad {f} is not convex CCW");
            let (area, flux) = quad_area_and_flux(&x);
            assert_close("quad area", area, h * h, 1e-12, 0.0);
            assert!(flux > 0.0, "quad {f} flux {flux:e}");
            per_face[2 * axis + usize::from(outward > 0.0)] += 1;
        }
        assert_eq!(per_face, [(n * n) as usize; 6], "quads per face, n = {n}");
    }
}

/// The surface nodes are exactly the last `surface_nodes` nodes: every
/// node on the boundary is one of them and none of the first ones is;
/// quads use only surface nodes.
#[test]
fn surface_nodes_are_last() {
    for n in LEVELS {
        let c = cube(A, n);
        let first = c.size.nodes - c.size.surface_nodes;
        for (i, x) in c.positions.iter().enumerate() {
            let on_surface = x.iter().any(|v| (v.abs() - 0.5 * A).abs() < 1e-15);
            assert_eq!(on_surface, i >= first, "node {i} at {x:?} (n = {n})");
        }
        for q in &c.quads {
            assert!(q.iter().all(|&id| id as usize >= first));
        }
        // Node ids are a permutation: no two nodes at one point.
        let mut sorted: Vec<[i64; 3]> = c
            .positions
            .iter()
            .map(|x| x.map(|v| (v / A * 1e6).round() as i64))
            .collect();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), c.size.nodes, "duplicate nodes, n = {n}");
    }
}

/// `node_quads` lists, per surface node, exactly the quads that contain it
/// (in quad order, each once), 3 at a corner and 4 elsewhere, the unused
/// slots `u32::MAX` at the end.
#[test]
fn node_quads_are_consistent() {
    for n in LEVELS {
        let c = cube(A, n);
        let first = c.size.nodes - c.size.surface_nodes;
        for (s, slots) in c.node_quads.iter().enumerate() {
            let id = (first + s) as u32;
            let listed: Vec<u32> = slots.iter().copied().filter(|&q| q != u32::MAX).collect();
            let used = listed.len();
            assert!(
                slots[used..].iter().all(|&q| q == u32::MAX),
                "gap in {slots:?}"
            );
            for &q in &listed {
                assert!(
                    c.quads[q as usize].contains(&id),
                    "node {id} lists quad {q} {:?}",
                    c.quads[q as usize]
                );
            }
            let containing: Vec<u32> = (0..c.quads.len() as u32)
                .filter(|&q| c.quads[q as usize].contains(&id))
                .collect();
            assert_eq!(listed, containing, "node {id}, n = {n}");
            let x = c.positions[id as usize];
            let corner = x.iter().all(|v| (v.abs() - 0.5 * A).abs() < 1e-15);
            assert_eq!(used, if corner { 3 } else { 4 }, "node {id} at {x:?}");
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    assert!(matches!(
        cube_size(0),
        Err(MeshError::InvalidParameter { field: "n", .. })
    ));
    assert!(cube_size(100_000).is_err());
    let size = cube_size(2).unwrap();
    let mut positions = vec![[0.0; 3]; size.nodes];
    let mut hexes = vec![[0; 8]; size.hexes];
    let mut quads = vec![[0; 4]; size.quads];
    let mut node_quads = vec![[0; 4]; size.surface_nodes];
    let mut scratch = vec![0; size.scratch];
    let mut out = MeshBuffers {
        positions: &mut positions,
        hexes: &mut hexes,
        quads: &mut quads,
        node_quads: &mut node_quads,
        scratch: &mut scratch,
    };
    for side in [0.0, -A, Real::NAN, Real::INFINITY] {
        assert!(
            matches!(
                generate_cube(side, 2, &mut out),
                Err(MeshError::InvalidParameter { field: "side", .. })
            ),
            "side {side}"
        );
    }
    assert!(generate_cube(A, 0, &mut out).is_err());
    // Buffers sized for n = 2 do not fit n = 3.
    assert!(matches!(
        generate_cube(A, 3, &mut out),
        Err(MeshError::BufferLength {
            buffer: "positions",
            ..
        })
    ));
    assert!(generate_cube(A, 2, &mut out).is_ok());
    let mut short = vec![0; size.scratch - 1];
    out.scratch = &mut short;
    assert!(matches!(
        generate_cube(A, 2, &mut out),
        Err(MeshError::BufferLength {
            buffer: "scratch",
            ..
        })
    ));
}
