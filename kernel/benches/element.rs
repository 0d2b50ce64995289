//! Criterion benches of the element loop: ns per element-step (forces +
//! constitutive update + hourglass + assembly) on the standard 1280-hex
//! granule of type B2, in a uniaxial-strain field with a little shear:
//! elastic (0.1 % from the virgin state) and plastic (the step from 19.99 %
//! to 20 %, the state loaded there in 2000 increments, as in an explicit
//! run), for the one-point element and the F-bar verification element.
//! Also one granule's whole predictor and corrector (elements, damping,
//! the velocity and position updates under selective mass scaling), and the
//! memory bandwidth (STREAM triad) and the core clock (a chain of dependent
//! additions) for the element's roofline.

use core::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use granbed_kernel::element::batch::{ElementBatch, ElementPath, batch_count, has_avx2, regroup};
use granbed_kernel::element::reference::{HexReference, hex_reference};
use granbed_kernel::granule::damping::RigidFrame;
use granbed_kernel::granule::dynamics::{
    GranuleBuffers, Loads, StepSizes, correct, correct_in, predict, predict_in,
};
use granbed_kernel::granule::forces::{ElementKind, ElementSettings, internal_forces_on};
use granbed_kernel::material::GranuleType;
use granbed_kernel::mesh::octant::MeshView;
use granbed_kernel::mesh::reference::{ReferenceMesh, compute_element_data};
use granbed_kernel::mesh::sphere::{MeshBuffers, SphereMeshParams, generate};
use granbed_kernel::tensor::VOIGT_IDENTITY;

struct Mesh {
    positions: Vec<[f64; 3]>,
    hexes: Vec<[u32; 8]>,
    quads: Vec<[u32; 4]>,
    node_quads: Vec<[u32; 4]>,
    elements: Vec<HexReference>,
    batches: Vec<ElementBatch>,
    node_volume: Vec<f64>,
    surface: usize,
}

fn standard_mesh() -> Mesh {
    let p = SphereMeshParams::standard();
    let s = p.size().unwrap();
    let mut m = Mesh {
        positions: vec![[0.0; 3]; s.nodes],
        hexes: vec![[0; 8]; s.hexes],
        quads: vec![[0; 4]; s.quads],
        node_quads: vec![[0; 4]; s.surface_nodes],
        elements: Vec::new(),
        batches: Vec::new(),
        node_volume: vec![0.0; s.nodes],
        surface: s.surface_nodes,
    };
    let mut scratch = vec![0; s.scratch];
    generate(
        &p,
        &mut MeshBuffers {
            positions: &mut m.positions,
            hexes: &mut m.hexes,
            quads: &mut m.quads,
            node_quads: &mut m.node_quads,
            scratch: &mut scratch,
        },
    )
    .unwrap();
    let first: [[f64; 3]; 8] = core::array::from_fn(|i| m.positions[m.hexes[0][i] as usize]);
    m.elements = vec![hex_reference(&first).unwrap(); s.hexes];
    let view = MeshView {
        positions: &m.positions,
        hexes: &m.hexes,
        quads: &m.quads,
        surface_nodes: m.surface,
    };
    compute_element_data(&view, &mut m.elements, &mut m.node_volume).unwrap();
    m.batches = vec![ElementBatch::ZERO; batch_count(s.hexes)];
    regroup(&m.elements, &mut m.batches).unwrap();
    m
}

fn bench_elements(c: &mut Criterion) {
    let m = standard_mesh();
    let mesh = ReferenceMesh {
        mesh: MeshView {
            positions: &m.positions,
            hexes: &m.hexes,
            quads: &m.quads,
            surface_nodes: m.surface,
        },
        node_quads: &m.node_quads,
        elements: &m.elements,
        batches: &m.batches,
        node_volume: &m.node_volume,
    };
    let mat = GranuleType::B2.params().validate().unwrap();
    let mut group = c.benchmark_group("element_step");
    group.throughput(Throughput::Elements(m.hexes.len() as u64));
    for (name, kind, squeeze) in [
        ("one_point_elastic", ElementKind::OnePoint, 0.999),
        ("one_point_plastic", ElementKind::OnePoint, 0.8),
        ("fbar_plastic", ElementKind::FBar, 0.8),
    ] {
        let settings = ElementSettings {
            kind,
            update: Default::default(),
            hourglass_kappa: 0.05,
        };
        // Uniaxial-strain field with a little shear, so every element has a general stress.
        let x: Vec<[f64; 3]> = m
            .positions
            .iter()
            .map(|p| [p[0] + 0.05 * (1.0 - squeeze) * p[2], p[1], p[2] * squeeze])
            .collect();
        // Start every step from the virgin state, so each element-step does the same work.
        let start = vec![VOIGT_IDENTITY; m.hexes.len() * settings.points_per_element()];
        let mut cp = start.clone();
        let mut f = vec![[0.0; 3]; m.positions.len()];
        // The one-point element on each path (the same bits; the default
        // is the fastest the processor has); F-bar has one path.
        let paths: &[(&str, ElementPath)] = match kind {
            ElementKind::OnePoint => &[
                ("scalar", ElementPath::Scalar),
                ("batched", ElementPath::Batched),
                ("avx2", ElementPath::Avx2),
            ],
            ElementKind::FBar => &[("scalar", ElementPath::Scalar)],
        };
        for &(path_name, path) in paths {
            if path == ElementPath::Avx2 && !has_avx2() {
                continue;
            }
            group.bench_function(format!("{name}/{path_name}"), |b| {
                b.iter(|| {
                    cp.copy_from_slice(&start);
                    let s = internal_forces_on(
                        path,
                        &mesh,
                        &mat,
                        &settings,
                        black_box(&x),
                        &mut cp,
                        &mut f,
                    )
                    .unwrap();
                    black_box(s.plastic_elements)
                })
            });
        }
    }
    group.finish();
}

/// The buffers of one granule, owned (the kernel's `GranuleBuffers`
/// borrows them).
struct GranuleStore {
    x: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    v_star: Vec<[f64; 3]>,
    x_pred: Vec<[f64; 3]>,
    f_int: Vec<[f64; 3]>,
    f_c: Vec<[f64; 3]>,
    f_d: Vec<[f64; 3]>,
    mass: Vec<f64>,
    fixed: Vec<u8>,
    cp_inv: Vec<granbed_kernel::tensor::Voigt>,
}

impl GranuleStore {
    /// Positions, velocities and contact forces back to the given start;
    /// the kernel's view of the buffers.
    fn reset(&mut self, x: &[[f64; 3]], v: &[[f64; 3]], f_c: &[[f64; 3]]) -> GranuleBuffers<'_> {
        self.x.copy_from_slice(x);
        self.v.copy_from_slice(v);
        self.f_c.copy_from_slice(f_c);
        GranuleBuffers {
            x: &mut self.x,
            v: &mut self.v,
            v_star: &mut self.v_star,
            x_pred: &mut self.x_pred,
            f_int: &mut self.f_int,
            f_c: &mut self.f_c,
            f_d: &mut self.f_d,
            mass: &mut self.mass,
            fixed: &mut self.fixed,
            cp_inv: &mut self.cp_inv,
        }
    }
}

/// One granule's step halves on the standard mesh, B2, selective mass
/// scaling ×10 (the bed's default until session 18, ×20 since): `predict` (elements + damping +
/// predictor) and `correct` (contact forces on the surface nodes only, as
/// in a bed), each from the same start every iteration; `framed` is given
/// the rigid frame, which the bed takes once per step for both halves
/// (`predict_in`, `correct_in`). Reported per node-step (1 501 nodes).
fn bench_granule_step(c: &mut Criterion) {
    let m = standard_mesh();
    let mesh = ReferenceMesh {
        mesh: MeshView {
            positions: &m.positions,
            hexes: &m.hexes,
            quads: &m.quads,
            surface_nodes: m.surface,
        },
        node_quads: &m.node_quads,
        elements: &m.elements,
        batches: &m.batches,
        node_volume: &m.node_volume,
    };
    let mat = GranuleType::B2.params().validate().unwrap();
    let settings = ElementSettings {
        kind: ElementKind::OnePoint,
        update: Default::default(),
        hourglass_kappa: 0.05,
    };
    let n = m.positions.len();
    let first_surface = n - m.surface;
    let factor = 10.0;
    let mass: Vec<f64> = m
        .node_volume
        .iter()
        .map(|v| factor * mat.density0 * v)
        .collect();
    // Squeezed 0.1 %, spinning slowly and swelling a little; a contact
    // force pressing every surface node inward.
    let x0: Vec<[f64; 3]> = m
        .positions
        .iter()
        .map(|p| [p[0] + 5e-5 * p[2], p[1], p[2] * 0.999])
        .collect();
    let v0: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| [0.3 * p[1] + 2.0 * p[0], -0.3 * p[0], 1e-3 + 2.0 * p[2]])
        .collect();
    let f_c0: Vec<[f64; 3]> = x0
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if i >= first_surface {
                p.map(|c| -1e-3 * c)
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let loads = Loads {
        gravity_m_s2: 9.81 / factor,
        damping_c: 2.0e3,
        rigid_modes: true,
        selective_mass_factor: factor,
    };
    let sizes = StepSizes {
        dt_prev: 1e-6,
        dt: 1e-6,
    };
    let start = vec![VOIGT_IDENTITY; m.hexes.len()];
    let mut store = GranuleStore {
        x: x0.clone(),
        v: v0.clone(),
        v_star: vec![[0.0; 3]; n],
        x_pred: vec![[0.0; 3]; n],
        f_int: vec![[0.0; 3]; n],
        f_c: f_c0.clone(),
        f_d: vec![[0.0; 3]; n],
        mass: mass.clone(),
        fixed: vec![0; n],
        cp_inv: start.clone(),
    };
    // The frame the bed takes once per step for both halves.
    let frame = RigidFrame::of(&mass, &x0);
    let mut group = c.benchmark_group("granule_step");
    group.throughput(Throughput::Elements(n as u64));
    for framed in [false, true] {
        let suffix = if framed { "/framed" } else { "" };
        group.bench_function(format!("predict_selective_x10{suffix}"), |bench| {
            bench.iter(|| {
                // `correct` below moves x and v: start from x0, v0 (the
                // configuration of `frame`) every time, and from the virgin
                // states (the corrector does not read them).
                store.cp_inv.copy_from_slice(&start);
                let mut b = store.reset(&x0, &v0, &f_c0);
                let s = if framed {
                    predict_in(&frame, None, &mesh, &mat, &settings, &mut b, sizes, &loads)
                } else {
                    predict(&mesh, &mat, &settings, &mut b, sizes, &loads)
                };
                black_box(s.unwrap().min_j)
            })
        });
        group.bench_function(format!("correct_selective_x10{suffix}"), |bench| {
            bench.iter(|| {
                let mut b = store.reset(&x0, &v0, &f_c0);
                let w = if framed {
                    correct_in(&frame, &mut b, sizes, &loads)
                } else {
                    correct(&mut b, sizes, &loads)
                }
                .expect("the bench's buffers fit");
                black_box(w.kinetic)
            })
        });
    }
    group.finish();
}

/// The roofline's memory side: the STREAM triad a = b + s c over three
/// arrays of 64 Mi doubles (1.5 GiB, beyond every cache), one thread;
/// criterion reports the bytes moved per second (24 per element: two
/// reads, one write; the write-allocate read not counted, as in STREAM).
fn bench_bandwidth(c: &mut Criterion) {
    const N: usize = 64 << 20;
    let b = vec![1.0f64; N];
    let cc = vec![2.0f64; N];
    let mut a = vec![0.0f64; N];
    let mut g = c.benchmark_group("memory_bandwidth");
    g.sample_size(10);
    g.throughput(Throughput::Bytes((24 * N) as u64));
    g.bench_function("triad_1_thread", |bench| {
        bench.iter(|| {
            let s = black_box(3.0);
            for ((a, b), c) in a.iter_mut().zip(&b).zip(&cc) {
                *a = b + s * c;
            }
            black_box(&a);
        })
    });
    g.finish();
}

/// The roofline's clock (the VM has no hardware counters, and
/// `/proc/cpuinfo` gives the nominal clock, not the boosted one): a chain
/// of 1 024 dependent f64 additions per iteration, which the compiler can
/// neither reorder nor vectorise (IEEE addition is not associative).
/// Criterion reports additions per second; an addition takes 3 cycles on
/// AMD Zen 3 and 4 (and on Intel since Skylake 4), so the clock is 3 (or
/// 4) × that rate.
fn bench_clock(c: &mut Criterion) {
    const ADDS: usize = 1024;
    let mut g = c.benchmark_group("clock");
    g.throughput(Throughput::Elements(ADDS as u64));
    g.bench_function("dependent_f64_adds", |bench| {
        let step = black_box(1.0e-300);
        bench.iter(|| {
            let mut x = black_box(0.0f64);
            for _ in 0..ADDS {
                x += step;
            }
            black_box(x)
        })
    });
    g.finish();
}

criterion_group!(
    benches,
    bench_elements,
    bench_granule_step,
    bench_bandwidth,
    bench_clock
);
criterion_main!(benches);
