//! The worst-element check (`granule::quality`): the smallest Gauss-point
//! Jacobian ratio of a deformed granule, with the reference determinants
//! taken once per mesh or on the way.

mod common;

use common::{Rng, sphere_mesh};
use granbed_kernel::Real;
use granbed_kernel::element::hex8::{gauss_points, jacobian};
use granbed_kernel::granule::quality::{
    WorstElement, reference_gauss_dets, worst_element, worst_element_against,
};
use granbed_kernel::mesh::octant::MeshView;
use granbed_kernel::mesh::reference::ReferenceMesh;
use granbed_kernel::mesh::sphere::SphereMeshParams;
use granbed_kernel::tensor::det_mat;

/// The standard sphere's mesh as the check reads it (connectivity and
/// reference positions only), with its reference determinants.
fn check<R>(f: impl FnOnce(&ReferenceMesh<'_>, &[[Real; 8]], &[[Real; 3]]) -> R) -> R {
    let m = sphere_mesh(&SphereMeshParams::standard());
    let mesh = ReferenceMesh {
        mesh: MeshView {
            positions: &m.positions,
            hexes: &m.hexes,
            quads: &m.quads,
            surface_nodes: m.size.surface_nodes,
        },
        node_quads: &m.node_quads,
        elements: &[],
        batches: &[],
        node_volume: &[],
    };
    let mut dets = vec![[0.0; 8]; m.hexes.len()];
    reference_gauss_dets(&mesh, &mut dets).expect("one per hex");
    f(&mesh, &dets, &m.positions)
}

fn bits(w: Option<WorstElement>) -> Option<(u64, usize)> {
    w.map(|w| (w.ratio.to_bits(), w.element))
}

/// The check written out as its definition: each element's Jacobians at
/// the Gauss points (shape gradients taken at each point) now and then,
/// their ratios in (element, point) order; the first NaN if there is one,
/// else the first of the smallest.
fn worst_by_definition(mesh: &ReferenceMesh<'_>, x: &[[Real; 3]]) -> Option<WorstElement> {
    let positions = mesh.mesh.positions;
    let ratios: Vec<WorstElement> = mesh
        .mesh
        .hexes
        .iter()
        .enumerate()
        .flat_map(|(element, hex)| {
            let now: [[Real; 3]; 8] = core::array::from_fn(|i| x[hex[i] as usize]);
            let then: [[Real; 3]; 8] = core::array::from_fn(|i| positions[hex[i] as usize]);
            gauss_points().map(|g| WorstElement {
                ratio: det_mat(&jacobian(&now, g)) / det_mat(&jacobian(&then, g)),
                element,
            })
        })
        .collect();
    let smallest = ratios
        .iter()
        .map(|w| w.ratio)
        .fold(Real::INFINITY, Real::min);
    ratios
        .iter()
        .find(|w| w.ratio.is_nan())
        .or_else(|| ratios.iter().find(|w| w.ratio == smallest))
        .copied()
}

/// With the determinants taken once or on the way, the same worst element
/// to the bit as the check's definition, on randomly distorted granules; a
/// wrong-length table is refused by `reference_gauss_dets`, and it and
/// another mesh's table are ignored by the check.
#[test]
fn cached_reference_determinants_give_the_same_bits() {
    check(|mesh, dets, x0| {
        let mut rng = Rng::new(31);
        for amplitude in [1e-6, 1e-5, 3e-5] {
            let x: Vec<[Real; 3]> = x0
                .iter()
                .map(|p| core::array::from_fn(|a| p[a] * 0.9 + rng.uniform(-amplitude, amplitude)))
                .collect();
            let want = worst_by_definition(mesh, &x);
            assert!(want.is_some());
            assert_eq!(bits(worst_element(mesh, &x)), bits(want));
            assert_eq!(bits(worst_element_against(mesh, dets, &x)), bits(want));
            assert_eq!(
                bits(worst_element_against(mesh, &dets[1..], &x)),
                bits(want)
            );
            // Another mesh's table (here: a stretched one) is not used.
            let other: Vec<[Real; 8]> = dets.iter().map(|d| d.map(|v| 2.0 * v)).collect();
            assert_eq!(bits(worst_element_against(mesh, &other, &x)), bits(want));
        }
        let mut short = vec![[0.0; 8]; dets.len() - 1];
        assert_eq!(reference_gauss_dets(mesh, &mut short), Err(dets.len()));
    });
}

/// A uniform stretch by s multiplies every Gauss-point Jacobian by s³.
#[test]
fn a_uniform_stretch_gives_its_volume_ratio() {
    check(|mesh, dets, x0| {
        for s in [0.5, 0.93, 1.2] {
            let x: Vec<[Real; 3]> = x0.iter().map(|p| p.map(|v| v * s)).collect();
            let w = worst_element_against(mesh, dets, &x).expect("elements");
            let want = s * s * s;
            assert!(
                (w.ratio - want).abs() <= 1e-12 * want,
                "s {s}: ratio {} against {want}",
                w.ratio
            );
        }
    });
}

/// A node pushed through its neighbourhood folds an element that holds it
/// (ratio ≤ 0), and a NaN position is reported as NaN, not skipped.
#[test]
fn a_folded_element_and_a_nan_are_found() {
    check(|mesh, dets, x0| {
        let hexes = mesh.mesh.hexes;
        let node = hexes[0][6] as usize;
        let other = hexes[0][0] as usize;
        let mut x = x0.to_vec();
        // Node 6 of element 0 moved past its opposite corner, node 0.
        x[node] = core::array::from_fn(|a| x0[other][a] - 0.5 * (x0[node][a] - x0[other][a]));
        let w = worst_element_against(mesh, dets, &x).expect("elements");
        assert!(w.ratio <= 0.0, "ratio {}", w.ratio);
        assert!(
            hexes[w.element].contains(&(node as u32)),
            "element {}",
            w.element
        );

        let mut x = x0.to_vec();
        x[hexes[7][3] as usize][1] = Real::NAN;
        let w = worst_element_against(mesh, dets, &x).expect("elements");
        assert!(w.ratio.is_nan());
        assert!(hexes[w.element].contains(&hexes[7][3]));
    });
}

/// Positions shorter than the mesh (or a hex naming a node past them) give
/// a NaN ratio at the first element that reads a missing node, as a
/// position that is not finite does, instead of an index panic (the
/// kernel API review of session 55); the reference table of such a mesh
/// holds NaN rows.
#[test]
fn a_node_the_positions_lack_is_reported_as_nan() {
    check(|mesh, dets, x0| {
        let hexes = mesh.mesh.hexes;
        let short = &x0[..10];
        let first = hexes
            .iter()
            .position(|h| h.iter().any(|&n| n as usize >= short.len()))
            .unwrap();
        for w in [
            worst_element(mesh, short),
            worst_element_against(mesh, dets, short),
        ] {
            let w = w.expect("elements");
            assert!(w.ratio.is_nan(), "ratio {}", w.ratio);
            assert_eq!(w.element, first);
        }
        let mut bad_hexes = hexes.to_vec();
        bad_hexes[3][5] = 1_000_000;
        let bad = ReferenceMesh {
            mesh: MeshView {
                hexes: &bad_hexes,
                ..mesh.mesh
            },
            ..*mesh
        };
        let mut table = vec![[0.0; 8]; hexes.len()];
        reference_gauss_dets(&bad, &mut table).unwrap();
        assert!(table[3].iter().all(|d| d.is_nan()));
        assert!(table[2].iter().all(|d| d.is_finite()));
        assert_eq!(worst_element(&bad, x0).map(|w| w.element), Some(3));
    });
}
