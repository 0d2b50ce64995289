//! Oracles of the cubed-sphere mesh and its reference element data
//! (physics.md §2.4, §3.4, E4).

// Index loops over xyz components read best here.
#![allow(clippy::needless_range_loop)]

mod common;

use common::{assert_close, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::element::hex8;
use granbed_kernel::element::reference::hex_reference;
use granbed_kernel::mesh::sphere::{MeshBuffers, MeshError, SphereMeshParams, generate};
use granbed_kernel::mesh::surface::area_and_volume;

const R: Real = 0.5e-3;

fn sphere_volume() -> Real {
    4.0 / 3.0 * core::f64::consts::PI * R * R * R
}

#[test]
fn standard_mesh_counts() {
    let m = sphere_mesh(&SphereMeshParams::standard());
    assert_eq!(
        (
            m.size.hexes,
            m.size.nodes,
            m.size.quads,
            m.size.surface_nodes
        ),
        (1280, 1501, 384, 386)
    );
    let c = sphere_mesh(&SphereMeshParams::new(R, 4, 1));
    assert_eq!((c.size.hexes, c.size.nodes), (160, 223));
    let f = SphereMeshParams::new(R, 16, 4).size().unwrap();
    assert_eq!(f.hexes, 16 * 16 * 16 + 6 * 16 * 16 * 4);
}

/// E4 and §3.4: volume 0.514836 mm³ = 0.98326 V_sphere (element sum equals
/// the surface-divergence volume to round-off), S = 3.11550 mm², α_SV =
/// 6.0514 (d = 1 mm) and 6.0175 (d_V), min scaled Jacobian 0.695, element
/// volume ratio 2.88, L_e from 0.0493 to 0.0796 mm. The published figures
/// carry 4–6 significant digits; tolerances match their last digit.
#[test]
fn standard_mesh_geometry() {
    let m = sphere_mesh(&SphereMeshParams::standard());
    let mut volume = 0.0;
    let (mut vmin, mut vmax) = (Real::MAX, 0.0 as Real);
    let (mut lmin, mut lmax) = (Real::MAX, 0.0 as Real);
    let mut min_scaled = Real::MAX;
    for e in 0..m.size.hexes {
        let x = m.hex_coords(e);
        let r = hex_reference(&x).expect("positive Jacobians");
        volume += r.volume;
        vmin = vmin.min(r.volume);
        vmax = vmax.max(r.volume);
        let l = r.volume / hex8::max_face_area(&x);
        lmin = lmin.min(l);
        lmax = lmax.max(l);
        for corner in 0..8 {
            min_scaled = min_scaled.min(hex8::corner_scaled_jacobian(&x, corner));
        }
    }
    assert_close("V_mesh", volume, 0.514836e-9, 2e-6, 0.0);
    assert_close("V/V_sphere", volume / sphere_volume(), 0.98326, 1e-5, 0.0);
    let (area, div_volume) = area_and_volume(&m.positions, &m.quads).unwrap();
    assert_close("divergence volume", div_volume, volume, 1e-12, 0.0);
    assert_close("S_mesh", area, 3.11550e-6, 2e-6, 0.0);
    assert_close(
        "alpha_SV (d = 1 mm)",
        1e-3 * area / volume,
        6.0514,
        2e-5,
        0.0,
    );
    let d_v = (6.0 * volume / core::f64::consts::PI).cbrt();
    assert_close("alpha_SV (d_V)", d_v * area / volume, 6.0175, 2e-5, 0.0);
    assert_close("min scaled Jacobian", min_scaled, 0.695, 0.0, 5e-4);
    assert_close("volume ratio", vmax / vmin, 2.88, 0.0, 5e-3);
    assert_close("min L_e", lmin, 0.0493e-3, 0.0, 0.00005e-3);
    assert_close("max L_e", lmax, 0.0796e-3, 0.0, 0.00005e-3);
}

/// §3.4: 1 − V_mesh/V_sphere = 0.065, 0.0167, 0.0042, 0.00106 for n = 4, 8,
/// 16, 32, i.e. O(h²): each halving of h divides it by ≈ 4.
#[test]
fn volume_converges_at_second_order() {
    let published = [0.065, 0.0167, 0.0042, 0.00106];
    let mut deficits = [0.0; 4];
    for (k, n) in [4u32, 8, 16, 32].into_iter().enumerate() {
        let m = sphere_mesh(&SphereMeshParams::new(R, n, (n / 4).max(1)));
        let (_, v) = area_and_volume(&m.positions, &m.quads).unwrap();
        deficits[k] = 1.0 - v / sphere_volume();
        let digits: Real = if k == 0 { 5e-4 } else { 5e-5 };
        assert_close(
            &format!("deficit n = {n}"),
            deficits[k],
            published[k],
            0.0,
            digits.max(published[k] * 0.01),
        );
    }
    // Asymptotic ratio 4; the coarsest pair is still pre-asymptotic (3.9).
    for k in 1..4 {
        let ratio = deficits[k - 1] / deficits[k];
        assert!(
            (3.85..4.05).contains(&ratio),
            "n = {}: ratio {ratio}",
            4 << k
        );
    }
}

/// Outward, counter-clockwise quads on the last 6n²+2 nodes; poles are nodes
/// on the sphere; every surface node sees 3 (the 8 cube corners) or 4 quads.
#[test]
fn surface_topology() {
    let m = sphere_mesh(&SphereMeshParams::standard());
    let first = (m.size.nodes - m.size.surface_nodes) as u32;
    let mut corners = 0;
    for (s, slots) in m.node_quads.iter().enumerate() {
        let count = slots.iter().filter(|q| **q != u32::MAX).count();
        assert!(
            count == 3 || count == 4,
            "surface node {s} has {count} quads"
        );
        corners += usize::from(count == 3);
        for &q in slots.iter().filter(|q| **q != u32::MAX) {
            assert!(m.quads[q as usize].contains(&(first + s as u32)));
        }
        let x = m.positions[first as usize + s];
        assert_close(
            "surface node radius",
            (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt(),
            R,
            1e-15,
            0.0,
        );
    }
    assert_eq!(corners, 8);
    for q in &m.quads {
        assert!(q.iter().all(|&id| id >= first));
        let x: [[Real; 3]; 4] = core::array::from_fn(|i| m.positions[q[i] as usize]);
        let (_, flux) = granbed_kernel::mesh::surface::quad_area_and_flux(&x);
        assert!(flux > 0.0, "outward normal");
    }
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let pole = m
                .positions
                .iter()
                .any(|x| (0..3).all(|a| x[a] == if a == axis { sign * R } else { 0.0 }));
            assert!(pole, "pole {sign} on axis {axis} is a node");
        }
    }
}

/// §2.4 oracle 3 and §2.1: Σγ0 = 0, Σγ0 X = 0, Σ B0 = 0 and Σ X ⊗ B0 = 1 for
/// every element (to 1e-15 in units of the element's own size).
#[test]
fn reference_vectors_are_orthogonal_to_linear_fields() {
    let m = sphere_mesh(&SphereMeshParams::standard());
    for e in 0..m.size.hexes {
        let x = m.hex_coords(e);
        let r = hex_reference(&x).unwrap();
        let h = r.volume.cbrt();
        for g in &r.gamma0 {
            assert!(g.iter().sum::<Real>().abs() < 1e-15);
            for a in 0..3 {
                let gx: Real = (0..8).map(|i| g[i] * x[i][a]).sum();
                assert!(gx.abs() < 1e-15 * h.max(R), "sum gamma0 X = {gx:e}");
            }
        }
        for a in 0..3 {
            assert!((0..8).map(|i| r.b0[i][a]).sum::<Real>().abs() * h < 1e-13);
            for b in 0..3 {
                let xb: Real = (0..8).map(|i| x[i][a] * r.b0[i][b]).sum();
                assert_close(
                    "sum X (x) B0",
                    xb,
                    if a == b { 1.0 } else { 0.0 },
                    0.0,
                    1e-13,
                );
            }
        }
        let share: Real = r.node_volume.iter().sum();
        assert_close("lumped volume shares", share, r.volume, 1e-14, 0.0);
    }
}

#[test]
fn bad_resolutions_and_buffers_are_errors() {
    assert_eq!(
        SphereMeshParams::new(R, 7, 2).size(),
        Err(MeshError::InvalidResolution { n: 7, m: 2 })
    );
    assert!(SphereMeshParams::new(R, 8, 0).size().is_err());
    for radius in [-R, 0.0, Real::NAN, Real::INFINITY] {
        assert!(
            matches!(
                SphereMeshParams::new(radius, 8, 2).size(),
                Err(MeshError::InvalidParameter {
                    field: "radius",
                    ..
                })
            ),
            "radius {radius}"
        );
    }
    let p = SphereMeshParams::standard();
    let s = p.size().unwrap();
    let mut pos = vec![[0.0; 3]; s.nodes - 1];
    let (mut hexes, mut quads) = (vec![[0; 8]; s.hexes], vec![[0; 4]; s.quads]);
    let (mut nq, mut scratch) = (vec![[0; 4]; s.surface_nodes], vec![0; s.scratch]);
    let err = generate(
        &p,
        &mut MeshBuffers {
            positions: &mut pos,
            hexes: &mut hexes,
            quads: &mut quads,
            node_quads: &mut nq,
            scratch: &mut scratch,
        },
    );
    assert_eq!(
        err,
        Err(MeshError::BufferLength {
            buffer: "positions",
            expected: s.nodes,
            got: s.nodes - 1
        })
    );
    // The parameter set physics.md §3.2 warns about inverts elements.
    let bad = SphereMeshParams {
        core_radius: 0.5,
        core_weight: 0.0,
        mid_weight: 0.5,
        ..p
    };
    let mut pos = vec![[0.0; 3]; s.nodes];
    let err = generate(
        &bad,
        &mut MeshBuffers {
            positions: &mut pos,
            hexes: &mut hexes,
            quads: &mut quads,
            node_quads: &mut nq,
            scratch: &mut scratch,
        },
    );
    assert!(
        matches!(err, Err(MeshError::InvertedElement { .. })),
        "{err:?}"
    );
}

/// Connectivity naming nodes the mesh does not have is an error of every
/// routine that indexes positions by it (it panicked before), and so is a
/// surface node count beyond the nodes.
#[test]
fn ids_out_of_range_are_errors_not_panics() {
    use granbed_kernel::mesh::octant::{MeshView, octant_size};
    use granbed_kernel::mesh::reference::compute_element_data;
    let m = sphere_mesh(&SphereMeshParams::new(R, 4, 1));
    let n = m.positions.len();
    let mut hexes = m.hexes.clone();
    hexes[3][5] = 99_999;
    let mut quads = m.quads.clone();
    quads[7][2] = 99_999;
    let view = |hexes, quads, surface_nodes| MeshView {
        positions: &m.positions,
        hexes,
        quads,
        surface_nodes,
    };
    let good = view(&m.hexes, &m.quads, m.size.surface_nodes);
    assert_eq!(good.check(), Ok(()));
    let bad_hex = view(&hexes, &m.quads, m.size.surface_nodes);
    let expected = Err(MeshError::NodeOutOfRange {
        buffer: "hexes",
        index: 3,
        id: 99_999,
        nodes: n,
    });
    assert_eq!(bad_hex.check(), expected);
    assert_eq!(octant_size(&bad_hex).map(|_| ()), expected);
    let mut elements = vec![hex_reference(&m.hex_coords(0)).unwrap(); m.hexes.len()];
    let mut node_volume = vec![0.0; n];
    assert_eq!(
        compute_element_data(&bad_hex, &mut elements, &mut node_volume),
        expected
    );
    let bad_quad = view(&m.hexes, &quads, m.size.surface_nodes);
    assert!(matches!(
        bad_quad.check(),
        Err(MeshError::NodeOutOfRange {
            buffer: "quads",
            index: 7,
            ..
        })
    ));
    assert_eq!(area_and_volume(&m.positions, &quads), None);
    // A quad naming an interior node: refused by check, and so by the
    // octant's extraction, which indexes its per-node surface table from
    // the first surface node (it overflowed: the kernel API review of
    // session 55).
    let first_surface = n - m.size.surface_nodes;
    let mut inward = m.quads.clone();
    inward[7][2] = 0;
    let bad_surface = view(&m.hexes, &inward, m.size.surface_nodes);
    let expected = Err(MeshError::NotSurfaceNode {
        quad: 7,
        id: 0,
        first_surface,
    });
    assert_eq!(bad_surface.check(), expected);
    let mut out = MeshBuffers {
        positions: &mut [],
        hexes: &mut [],
        quads: &mut [],
        node_quads: &mut [],
        scratch: &mut [],
    };
    assert_eq!(
        granbed_kernel::mesh::octant::extract_octant(&bad_surface, &mut out).map(|_| ()),
        expected
    );
    let too_many = view(&m.hexes, &m.quads, n + 1);
    assert!(matches!(
        octant_size(&too_many),
        Err(MeshError::NodeOutOfRange {
            buffer: "surface_nodes",
            ..
        })
    ));
}
