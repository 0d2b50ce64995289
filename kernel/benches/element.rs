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
use granbed_host::mesh::{MeshLevel, OwnedReference};
use granbed_host::store::GranuleStore;
use granbed_kernel::element::batch::{ElementPath, has_avx2};
use granbed_kernel::granule::damping::RigidFrame;
use granbed_kernel::granule::dynamics::{
    GranuleBuffers, Loads, StepSizes, correct, correct_in, predict, predict_in,
};
use granbed_kernel::granule::forces::{ElementKind, ElementSettings, internal_forces_on};
use granbed_kernel::material::GranuleType;
use granbed_kernel::tensor::VOIGT_IDENTITY;

/// The standard 1280-hex granule (radius 0.5 mm, 8x2) with its element
/// data, as the CLI and the browser build it (`granbed-host`).
fn standard_mesh() -> OwnedReference {
    OwnedReference::sphere(0.5e-3, MeshLevel::STANDARD, false).expect("the standard mesh")
}

fn bench_elements(c: &mut Criterion) {
    let m = standard_mesh();
    let mesh = m.view();
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

/// `store`'s positions, velocities and contact forces back to the given
/// start; the kernel's view of its buffers.
fn reset<'a>(
    store: &'a mut GranuleStore,
    x: &[[f64; 3]],
    v: &[[f64; 3]],
    f_c: &[[f64; 3]],
) -> GranuleBuffers<'a> {
    store.x.copy_from_slice(x);
    store.v.copy_from_slice(v);
    store.f_c.copy_from_slice(f_c);
    store.buffers()
}

/// One granule's step halves on the standard mesh, B2, selective mass
/// scaling ×10 (the bed's default until session 18, ×20 since): `predict` (elements + damping +
/// predictor) and `correct` (contact forces on the surface nodes only, as
/// in a bed), each from the same start every iteration; `framed` is given
/// the rigid frame, which the bed takes once per step for both halves
/// (`predict_in`, `correct_in`). Reported per node-step (1 501 nodes).
fn bench_granule_step(c: &mut Criterion) {
    let m = standard_mesh();
    let mesh = m.view();
    let mat = GranuleType::B2.params().validate().unwrap();
    let settings = ElementSettings {
        kind: ElementKind::OnePoint,
        update: Default::default(),
        hourglass_kappa: 0.05,
    };
    let n = m.positions.len();
    let first_surface = m.surface_range().start;
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
    let mut store = GranuleStore::new(&m, 1);
    store.mass.copy_from_slice(&mass);
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
                let mut b = reset(&mut store, &x0, &v0, &f_c0);
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
                let mut b = reset(&mut store, &x0, &v0, &f_c0);
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
