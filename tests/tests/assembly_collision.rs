//! Two granules colliding (physics.md §5.6 oracle 2): frictionless and
//! undamped, linear momentum is conserved to round-off, no interpenetration
//! remains, the contact never injects energy, and the rebound is sensible.

use granbed_cli::assembly::{Assembly, AssemblyParams, Placement};
use granbed_cli::model::{MeshLevel, OwnedReference};
use granbed_kernel::Real;
use granbed_kernel::granule::forces::{ElementKind, ElementSettings};
use granbed_kernel::material::{GranuleType, MaterialParams};

const R: Real = 0.5e-3;

fn elastic_params() -> AssemblyParams {
    let material = MaterialParams {
        yield_stress_pa: Real::INFINITY,
        friction: 0.0,
        ..GranuleType::B2.params()
    }
    .validate()
    .unwrap();
    let elements = ElementSettings {
        kind: ElementKind::OnePoint,
        update: Default::default(),
        hourglass_kappa: granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA,
    };
    AssemblyParams {
        damping_ratio: 0.0,
        gravity_m_s2: 0.0,
        ..AssemblyParams::standard(material, elements)
    }
}

struct Outcome {
    p0: [Real; 3],
    max_momentum_error: Real,
    min_gap: Real,
    final_gap: Real,
    v_a: [Real; 3],
    v_b: [Real; 3],
    kinetic0: Real,
    kinetic: Real,
    contact_work: Real,
    residual: Real,
    steps: u64,
}

/// Granule A at the origin moving at `v` towards B, at rest at `offset`.
fn collide(level: MeshLevel, offset: [Real; 3], v: [Real; 3], duration: Real) -> Outcome {
    let mesh = OwnedReference::sphere(R, level, false).unwrap();
    let a = Placement {
        velocity: v,
        ..Placement::at([0.0; 3])
    };
    let b = Placement::at(offset);
    let mut asm = Assembly::new(elastic_params(), &mesh, &[a, b], Vec::new()).unwrap();
    let p0 = asm.momentum();
    let m = asm.granule_mass(0);
    let kinetic0 = 0.5 * m * v.iter().map(|c| c * c).sum::<Real>();
    let scale = m * v.iter().map(|c| c * c).sum::<Real>().sqrt();
    let mut max_err: Real = 0.0;
    let mut min_gap: Real = 0.0;
    while asm.time() < duration {
        asm.step().unwrap();
        let p = asm.momentum();
        for k in 0..3 {
            max_err = max_err.max((p[k] - p0[k]).abs() / scale);
        }
        if asm.steps() % 10 == 0 {
            min_gap = min_gap.min(asm.penetration().unwrap());
        }
    }
    Outcome {
        p0,
        max_momentum_error: max_err,
        min_gap,
        final_gap: asm.penetration().unwrap(),
        v_a: asm.velocity(0),
        v_b: asm.velocity(1),
        kinetic0,
        kinetic: asm.energies().kinetic,
        contact_work: asm.energies().contact_work,
        residual: asm.energies().residual(),
        steps: asm.steps(),
    }
}

#[test]
fn head_on_collision_conserves_momentum_and_does_not_interpenetrate() {
    let v = 0.05;
    let o = collide(
        MeshLevel::new(4, 1),
        [2.0 * R + 5e-6, 0.0, 0.0],
        [v, 0.0, 0.0],
        1.5e-3,
    );
    eprintln!(
        "steps {} p0 {:?} err {:.3e} min_gap {:.3e} final {:.3e} vA {:?} vB {:?} K0 {:.4e} K {:.4e} Wc {:.3e} res {:.3e}",
        o.steps,
        o.p0,
        o.max_momentum_error,
        o.min_gap,
        o.final_gap,
        o.v_a,
        o.v_b,
        o.kinetic0,
        o.kinetic,
        o.contact_work,
        o.residual
    );
    assert!(
        o.max_momentum_error < 1e-12,
        "momentum drift {:.3e}",
        o.max_momentum_error
    );
    // Separated again, with B moving on and A slower or backwards.
    assert!(
        o.v_b[0] > 0.5 * v && o.v_a[0] < 0.5 * v,
        "vA {:?} vB {:?}",
        o.v_a,
        o.v_b
    );
    assert_eq!(
        o.final_gap, 0.0,
        "interpenetration left after the collision"
    );
    // Contact takes energy out, never puts it in.
    assert!(
        o.contact_work <= 1e-9 * o.kinetic0,
        "contact work {:.3e}",
        o.contact_work
    );
}
