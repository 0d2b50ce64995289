//! Criterion benches of the constitutive update: ns per integration-point
//! update on the elastic and plastic paths, for η0 = 0.6 (porous ellipse,
//! 2×2 Newton) and η0 = 1.0 (von Mises, radial return).
//!
//! Inputs are 256 (F_{n+1}, C_p⁻¹_n) pairs taken from a real uniaxial-strain
//! history (strain increments of 1e-4 on the plastic path, 1e-6 on the
//! elastic one so that 256 steps stay below yield),
//! built outside the timed loop; each iteration updates all 256 from a copy
//! of their start-of-step state.

use core::hint::black_box;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use granbed_kernel::constitutive::{UpdateOptions, update_point};
use granbed_kernel::material::GranuleType;
use granbed_kernel::tensor::{Mat3, VOIGT_IDENTITY, Voigt};

const POINTS: usize = 256;

/// (F_{n+1}, C_p⁻¹_n) pairs whose update is plastic (or elastic) for type `t`,
/// along an axial compression with a little shear so the stress is general.
fn history(t: GranuleType, plastic: bool) -> Vec<(Mat3, Voigt)> {
    let mat = t.params().validate().unwrap();
    let opts = UpdateOptions::default();
    let mut c = VOIGT_IDENTITY;
    let mut pairs = Vec::new();
    let mut n = 0;
    while pairs.len() < POINTS {
        n += 1;
        // Elastic pairs come from the start of the loading, at finer increments.
        let e = if plastic { 1e-4 } else { 1e-6 } * n as f64;
        let mut f = Mat3::from_diagonal(&[1.0 + 0.2 * e, 1.0 - 0.1 * e, 1.0 - e].into());
        f[(0, 1)] = 0.3 * e;
        let before = c;
        let up = update_point(&mat, &opts, &f, &mut c).unwrap();
        if up.info.plastic == plastic {
            pairs.push((f, before));
        }
        assert!(
            n < 1_000_000,
            "history never became {}",
            if plastic { "plastic" } else { "elastic" }
        );
    }
    pairs
}

fn bench_update(c: &mut Criterion) {
    let opts = UpdateOptions::default();
    let mut group = c.benchmark_group("constitutive_update");
    group.throughput(Throughput::Elements(POINTS as u64));
    for t in [GranuleType::B1, GranuleType::B3] {
        let mat = t.params().validate().unwrap();
        for plastic in [false, true] {
            let pairs = history(t, plastic);
            let name = format!(
                "{}_eta0_{}",
                if plastic { "plastic" } else { "elastic" },
                t.eta0()
            );
            group.bench_function(name, |b| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for (f, c0) in &pairs {
                        let mut state = *c0;
                        let up = update_point(&mat, &opts, black_box(f), &mut state).unwrap();
                        acc += up.tau[0];
                    }
                    black_box(acc)
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_update);
criterion_main!(benches);
