//! Criterion benches of granule contact: one node-to-quad projection on a
//! warped face, and a full contact pass (detection of both passes + the
//! kinematic forces) on a dense pair: two standard 1280-hex granules whose
//! surfaces overlap by 60 µm, as in a compressed bed; detection on that
//! pair trying every face against detection through per-node face lists
//! (and the lists' build).

use core::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use granbed_kernel::contact::broad::bounding_sphere;
use granbed_kernel::contact::face_lists::{
    AnchorSurface, FaceLists, FaceListsMut, ListLengths, ReachBox, build,
};
use granbed_kernel::contact::pair::{
    CandidateFace, Constraint, NodeForce, PairSettings, detect, detect_listed, forces,
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

/// One pass's face-list buffers: nodes, starts, faces, used.
type ListBuffers = (Vec<u32>, Vec<u32>, Vec<u32>, Vec<u32>);

/// `x`'s surface as the face lists' anchor.
fn anchor<'a>(m: &'a Sphere, x: &'a [[f64; 3]]) -> AnchorSurface<'a> {
    let first = x.len() - m.surface;
    AnchorSurface {
        x: &x[first..],
        first_surface: first,
        quads: &m.quads,
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
    c.bench_function("detect on a dense pair (every face)", |bench| {
        bench.iter(|| detect(&a, &b, &settings, &mut scratch, &mut constraints).unwrap())
    });
    // Face lists with the bed's default skin (0.02 of the mean face
    // diagonal, about 2.7 µm here), built on the same configuration.
    let (a_anchor, b_anchor) = (anchor(&m, &a_x), anchor(&m, &b_x));
    let drift = 2.7e-6;
    let mut reach = vec![ReachBox::default(); m.quads.len()];
    let mut lists = [(); 2].map(|_| {
        (
            vec![0u32; m.surface],
            vec![0u32; m.surface + 1],
            vec![0u32; 64 * m.surface],
            vec![0u32; m.quads.len()],
        )
    });
    let mut build_both = |lists: &mut [ListBuffers; 2]| {
        let mut lengths = [ListLengths::default(); 2];
        for (k, (slave, master)) in [(&a_anchor, &b_anchor), (&b_anchor, &a_anchor)]
            .into_iter()
            .enumerate()
        {
            let l = &mut lists[k];
            let out = FaceListsMut {
                nodes: &mut l.0,
                starts: &mut l.1,
                faces: &mut l.2,
                used: &mut l.3,
            };
            lengths[k] = build(
                slave,
                master,
                settings.window_fraction,
                drift,
                &mut reach,
                out,
            )
            .unwrap();
        }
        lengths
    };
    let len = build_both(&mut lists);
    eprintln!("face lists: {len:?}");
    c.bench_function("face lists of a dense pair (both passes)", |bench| {
        bench.iter(|| build_both(&mut lists))
    });
    let view = |k: usize| {
        let l = &lists[k];
        FaceLists {
            nodes: &l.0[..len[k].nodes],
            starts: &l.1[..len[k].nodes + 1],
            faces: &l.2[..len[k].faces],
            used: &l.3[..len[k].used],
        }
    };
    let (ab, ba) = (view(0), view(1));
    let mut slot = vec![u32::MAX; m.quads.len()];
    c.bench_function("detect on a dense pair (face lists)", |bench| {
        bench.iter(|| {
            detect_listed(
                &a,
                &b,
                &settings,
                [&ab, &ba],
                &mut scratch,
                &mut slot,
                &mut constraints,
            )
            .unwrap()
        })
    });
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
