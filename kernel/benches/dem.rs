//! Criterion benches of the discrete-element pour: one velocity-Verlet step
//! of a settled-looking 1000-sphere bed (the state after 150 000 steps of
//! the standard pour, seed 1), one Hertz–Mindlin contact evaluation, and
//! four contacts evaluated together in lanes (as the pour does).

use core::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use granbed_kernel::dem::contact::{
    ContactLanes, ContactLaw, hertz_beta, hertz_mindlin, hertz_mindlin_lanes,
};
use granbed_kernel::dem::neighbors::Pair;
use granbed_kernel::dem::pour::{PourBuffers, PourParams, PourScene};

fn bench_dem(c: &mut Criterion) {
    let p = PourParams::standard(1200.0, 1);
    let n = p.granules;
    let z = [0.0; 3];
    let empty = Pair { i: 0, j: 0, xi: z };
    let (mut x, mut v, mut w, mut f, mut t, mut xb) = (
        vec![z; n],
        vec![z; n],
        vec![z; n],
        vec![z; n],
        vec![z; n],
        vec![z; n],
    );
    let (mut pa, mut pb) = (vec![empty; 12 * n], vec![empty; 12 * n]);
    let (mut head, mut next) = (vec![0; p.grid().cells()], vec![0; n]);
    let buf = PourBuffers {
        x: &mut x,
        v: &mut v,
        omega: &mut w,
        f: &mut f,
        torque: &mut t,
        x_built: &mut xb,
        pairs: &mut pa,
        pairs_old: &mut pb,
        head: &mut head,
        next: &mut next,
    };
    let mut scene = PourScene::new(p, buf).unwrap();
    for _ in 0..150_000 {
        scene.step().unwrap();
    }
    let mut group = c.benchmark_group("dem");
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function("pour_step_1000_spheres", |b| {
        b.iter(|| scene.step().unwrap())
    });
    group.finish();

    let law = ContactLaw::sphere_sphere(100e6, 0.3, 0.5e-3, 6e-7, 0.1);
    let beta = hertz_beta(0.3);
    let n = [0.0, 0.6, 0.8];
    c.bench_function("dem/hertz_mindlin_contact", |b| {
        let mut xi = [1e-8, 0.0, 0.0];
        b.iter(|| {
            black_box(hertz_mindlin(
                &law,
                beta,
                black_box(1e-7),
                &n,
                &[1e-4, 2e-4, -1e-4],
                &mut xi,
                1e-6,
            ))
        })
    });
}

fn bench_lanes(c: &mut Criterion) {
    let law = ContactLaw::sphere_sphere(100e6, 0.3, 0.5e-3, 6e-7, 0.1);
    let beta = hertz_beta(0.3);
    let mut lanes = ContactLanes::<4>::ZERO;
    for l in 0..4 {
        lanes.set_law(l, &law);
        lanes.delta[l] = 1e-7 * (1.0 + 0.1 * l as f64);
        lanes.n[1][l] = 0.6;
        lanes.n[2][l] = 0.8;
        lanes.dv[0][l] = 1e-4;
        lanes.dv[1][l] = 2e-4;
        lanes.dv[2][l] = -1e-4;
        lanes.xi[0][l] = 1e-8;
    }
    let mut group = c.benchmark_group("dem");
    group.throughput(Throughput::Elements(4));
    group.bench_function("hertz_mindlin_4_lanes", |b| {
        b.iter(|| {
            let mut c = black_box(lanes);
            hertz_mindlin_lanes(&mut c, beta, 0.5e-3, 1e-6);
            black_box(c.force)
        })
    });
    group.finish();
}

criterion_group!(benches, bench_dem, bench_lanes);
criterion_main!(benches);
