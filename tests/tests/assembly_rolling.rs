//! A granule on a rigid inclined plane (physics.md §5.6 oracle 5): with
//! μ = 0.1 it rolls without slip at a = (5/7) g sin θ while tan θ < 3.5 μ,
//! and above that it rolls and slips with a = g (sin θ − μ cos θ).
//! The plane is tilted instead of gravity: inward normal (−sin θ, 0, cos θ)
//! through the origin, downhill d = (−cos θ, 0, −sin θ).

use granbed_cli::assembly::{Assembly, AssemblyParams, Placement, WallSpec};
use granbed_cli::model::{MeshLevel, OwnedReference};
use granbed_kernel::Real;
use granbed_kernel::analysis::fit::linear_fit;
use granbed_kernel::contact::wall::{Plane, Wall};
use granbed_kernel::granule::forces::{ElementKind, ElementSettings};
use granbed_kernel::material::GranuleType;

const R: Real = 0.5e-3;
const G: Real = 9.81;

/// Downhill acceleration of the centre of mass, m/s², fitted to the
/// velocity over (t_fit, t_end].
fn downhill_acceleration(theta_deg: Real, t_fit: Real, t_end: Real) -> Real {
    let theta = theta_deg.to_radians();
    let mesh = OwnedReference::sphere(R, MeshLevel::STANDARD, false).unwrap();
    let mut material = GranuleType::B2.params();
    material.yield_stress_pa = Real::INFINITY;
    material.friction = 0.1;
    let elements = ElementSettings {
        kind: ElementKind::OnePoint,
        update: Default::default(),
        hourglass_kappa: granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA,
    };
    let params = AssemblyParams::standard(material.validate().unwrap(), elements);
    let n = [-theta.sin(), 0.0, theta.cos()];
    let d = [-theta.cos(), 0.0, -theta.sin()];
    let slope = WallSpec::fixed(Wall::Plane(Plane {
        normal: n,
        offset: 0.0,
    }));
    let placed = [Placement::at(n.map(|c| c * R))];
    let mut asm = Assembly::new(params, &mesh, &placed, vec![slope]).unwrap();
    let (mut t, mut v) = (Vec::new(), Vec::new());
    while asm.time() < t_end {
        asm.step().unwrap();
        if asm.time() > t_fit {
            let u = asm.velocity(0);
            // v is v_{n−½}: its time is half a step back.
            t.push(asm.time() - 0.5 * asm.last().dt);
            v.push(u[0] * d[0] + u[1] * d[1] + u[2] * d[2]);
        }
    }
    linear_fit(t.iter().copied().zip(v.iter().copied()))
        .unwrap()
        .slope
}

#[test]
fn a_granule_rolls_without_slip_below_three_and_a_half_mu() {
    let theta: Real = 12.0;
    let a = downhill_acceleration(theta, 1e-3, 6e-3);
    let rolling = 5.0 / 7.0 * G * theta.to_radians().sin();
    let sliding = G * (theta.to_radians().sin() - 0.1 * theta.to_radians().cos());
    eprintln!("theta {theta}: a {a:.4} rolling {rolling:.4} sliding {sliding:.4}");
    assert!(
        (a / rolling - 1.0).abs() < 0.05,
        "a = {a:.4} vs (5/7) g sin θ = {rolling:.4}"
    );
}

#[test]
fn a_granule_slips_above_three_and_a_half_mu() {
    let theta: Real = 30.0;
    let a = downhill_acceleration(theta, 1e-3, 6e-3);
    let sliding = G * (theta.to_radians().sin() - 0.1 * theta.to_radians().cos());
    let rolling = 5.0 / 7.0 * G * theta.to_radians().sin();
    eprintln!("theta {theta}: a {a:.4} sliding {sliding:.4} rolling {rolling:.4}");
    assert!(
        (a / sliding - 1.0).abs() < 0.03,
        "a = {a:.4} vs g(sin θ − μ cos θ) = {sliding:.4}"
    );
}
