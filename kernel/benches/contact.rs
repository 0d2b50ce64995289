//! Criterion benches of granule contact: one node-to-quad projection on a
//! warped face, and a full contact pass (detection of both passes + the
//! kinematic forces) on a dense pair: two standard 1280-hex granules whose
//! surfaces overlap by 60 µm, as in a compressed bed.

use core::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use granbed_kernel::contact::broad::bounding_sphere;
use granbed_kernel::contact::pair::{
    CandidateFace, Constraint, NodeForce, PairSettings, detect, forces,
};
use granbed_kernel::contact::quad::project;
use granbed_kernel::contact::surface::{Aabb, SurfaceBody, quad_bounds};
use granbed_kernel::mesh::sphere::{MeshBuffers, SphereMeshParams, generate};

struct Sphere {
    positions: Vec<[f64; 3]>,
    quads: Vec<[u32; 4]>,
    node_quads: Vec<[u32; 4]>,
    surface: usize,
}

fn sphere() -> Sphere {
    let p = SphereMeshParams::standard();
    let s = p.size().unwrap();
    let mut m = Sphere {
        positions: vec![[0.0; 3]; s.nodes],
        quads: vec![[0; 4]; s.quads],
        node_quads: vec![[0; 4]; s.surface_nodes],
        surface: s.surface_nodes,
    };
    let mut hexes = vec![[0; 8]; s.hexes];
    let mut scratch = vec![0; s.scratch];
    generate(
        &p,
        &mut MeshBuffers {
            positions: &mut m.positions,
            hexes: &mut hexes,
            quads: &mut m.quads,
            node_quads: &mut m.node_quads,
            scratch: &mut scratch,
        },
    )
    .unwrap();
    m
}

fn body<'a>(
    m: &'a Sphere,
    x: &'a [[f64; 3]],
    mass: &'a [f64],
    quad_boxes: &'a [Aabb],
) -> SurfaceBody<'a> {
    let first = x.len() - m.surface;
    SurfaceBody {
        x_n: x,
        x_pred: x,
        mass,
        first_surface: first,
        quads: &m.quads,
        node_quads: &m.node_quads,
        bounds: Aabb::of_surface(x, first),
        sphere: bounding_sphere(x, first),
        quad_bounds: quad_boxes,
    }
}

fn benches(c: &mut Criterion) {
    let quad = [
        [0.0, 0.0, 0.0],
        [1e-4, 0.0, 3e-6],
        [1.1e-4, 1e-4, -2e-6],
        [-5e-6, 0.9e-4, 1e-6],
    ];
    let p = [4e-5, 6e-5, -1e-6];
    c.bench_function("project node on warped quad", |b| {
        b.iter(|| project(black_box(&p), black_box(&quad)))
    });

    let m = sphere();
    let a_x = m.positions.clone();
    // B overlaps A by 60 µm along a direction off the mesh axes.
    let dir = [0.6, 0.48, 0.64];
    let d = 1e-3 - 60e-6;
    let b_x: Vec<[f64; 3]> = m
        .positions
        .iter()
        .map(|x| core::array::from_fn(|k| x[k] + d * dir[k]))
        .collect();
    let mass = vec![1e-9; m.positions.len()];
    let boxes = |x: &[[f64; 3]]| {
        let mut out = vec![Aabb::EMPTY; m.quads.len()];
        quad_bounds(x, &m.quads, &mut out);
        out
    };
    let (a_boxes, b_boxes) = (boxes(&a_x), boxes(&b_x));
    let a = body(&m, &a_x, &mass, &a_boxes);
    let b = body(&m, &b_x, &mass, &b_boxes);
    let settings = PairSettings::standard(0.1);
    let mut scratch = vec![CandidateFace::default(); m.quads.len()];
    let mut constraints = vec![Constraint::default(); 1024];
    let n = detect(&a, &b, &settings, &mut scratch, &mut constraints).unwrap();
    eprintln!("dense pair: {n} constraints (both passes)");
    let mut out = vec![NodeForce::default(); 5 * 1024];
    c.bench_function("contact pass on a dense pair (detect + forces)", |bench| {
        bench.iter(|| {
            let n = detect(&a, &b, &settings, &mut scratch, &mut constraints).unwrap();
            forces(
                (&a, &[]),
                (&b, &[]),
                &constraints[..n],
                &settings,
                1e-12,
                &mut out,
            )
            .unwrap()
        })
    });
}

criterion_group!(contact, benches);
criterion_main!(contact);
