//! Granules at rest under gravity (physics.md §5.6 oracle 3 and issue #5's
//! block): the floor carries the weight, a 2-stack's bottom contact carries
//! the top granule, and a 3×3×3 simple-cubic block confined in a box has
//! its weight balanced by the floor and the walls' friction, 6 contacts at
//! the centre granule and a coordination number of 4.

use granbed_cli::assembly::{Assembly, AssemblyParams, Placement, WallSpec};
use granbed_cli::model::{MeshLevel, OwnedReference};
use granbed_kernel::Real;
use granbed_kernel::contact::wall::{Plane, Wall};
use granbed_kernel::granule::forces::{ElementKind, ElementSettings};
use granbed_kernel::material::{GranuleType, Material};

const R: Real = 0.5e-3;
const G: Real = 9.81;

/// B2 granules, plastic (`elastic` false) or with σ_y = ∞.
fn params_of(elastic: bool) -> AssemblyParams {
    let mut material = GranuleType::B2.params();
    if elastic {
        material.yield_stress_pa = Real::INFINITY;
    }
    let material: Material = material.validate().unwrap();
    let elements = ElementSettings {
        kind: ElementKind::OnePoint,
        update: Default::default(),
        hourglass_kappa: granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA,
    };
    AssemblyParams::standard(material, elements)
}

fn params() -> AssemblyParams {
    params_of(false)
}

fn plane(normal: [Real; 3], offset: Real) -> WallSpec {
    WallSpec::fixed(Wall::Plane(Plane { normal, offset }))
}

/// Time averages over the last `window` seconds of a run of `duration`.
#[derive(Debug, Default)]
struct Averages {
    /// Per wall: normal force, N.
    wall_normal: Vec<Real>,
    /// Per wall: z component of the friction force on the granules, N.
    wall_friction_z: Vec<Real>,
    /// Σ F_n over granule pairs, N.
    pair_normal: Real,
    /// z component of the force on the first granule of the first pair, N.
    first_pair_force_z: Real,
    /// Per granule, the number of steps of the window it touched each
    /// other granule in, summed (divided by the step count at the end).
    contacts: Vec<Real>,
    /// Pairs in contact at every step of the window.
    persistent_pairs: usize,
}

fn run(asm: &mut Assembly<'_>, duration: Real, window: Real) -> Averages {
    let walls = asm.walls().count();
    let n = asm.granules().len();
    let mut avg = Averages {
        wall_normal: vec![0.0; walls],
        wall_friction_z: vec![0.0; walls],
        contacts: vec![0.0; n],
        ..Averages::default()
    };
    let mut time = 0.0;
    let mut steps = 0usize;
    let mut always: Option<Vec<bool>> = None;
    while asm.time() < duration {
        asm.step().unwrap();
        if asm.time() < duration - window {
            continue;
        }
        let dt = asm.last().dt;
        time += dt;
        steps += 1;
        for (k, w) in asm.last().walls.iter().enumerate() {
            avg.wall_normal[k] += w.normal * dt;
            avg.wall_friction_z[k] += w.tangential[2] * dt;
        }
        avg.pair_normal += asm.last().pair_normal * dt;
        if let Some(w) = asm.contact().work().first() {
            avg.first_pair_force_z += w.step.total_on_a[2] * dt;
        }
        for (c, k) in avg
            .contacts
            .iter_mut()
            .zip(asm.contact().contacts_per_granule())
        {
            *c += k as Real;
        }
        let now: Vec<bool> = asm.contact().work().iter().map(|w| w.touching()).collect();
        always = Some(match always {
            Some(prev) if prev.len() == now.len() => {
                prev.iter().zip(&now).map(|(a, b)| *a && *b).collect()
            }
            _ => now,
        });
    }
    for v in avg.wall_normal.iter_mut().chain(&mut avg.wall_friction_z) {
        *v /= time;
    }
    avg.pair_normal /= time;
    avg.first_pair_force_z /= time;
    for c in &mut avg.contacts {
        *c /= steps as Real;
    }
    avg.persistent_pairs = always.map_or(0, |a| a.iter().filter(|x| **x).count());
    avg
}

/// A two-granule stack is an unstable equilibrium (on the faceted mesh a
/// node resting on a vertex is pushed along one face's normal, which leans
/// ~11° on the 4x1 mesh: a free stack topples within 20 ms). It stands in
/// a frictionless tube of its own radius, which carries no vertical load.
#[test]
fn a_two_stack_rests_on_the_floor_with_its_weight() {
    let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
    let placed = [
        Placement::at([0.0, 0.0, R]),
        Placement::at([0.0, 0.0, 3.0 * R]),
    ];
    let floor = plane([0.0, 0.0, 1.0], 0.0);
    let tube = WallSpec::fixed(Wall::Die { radius: R });
    let mut p = params();
    p.wall_friction = 0.0;
    let mut asm = Assembly::new(p, &mesh, &placed, vec![floor, tube]).unwrap();
    let mg = asm.granule_mass(0) * G;
    // Kinematic contact takes energy out only slowly from the rigid
    // rattling: average over many rattles (the mean force is the weight
    // up to Δp/T).
    let avg = run(&mut asm, 60e-3, 40e-3);
    eprintln!("mg {mg:.4e} {avg:?}");
    let floor = avg.wall_normal[0];
    assert!(
        (floor / (2.0 * mg) - 1.0).abs() < 0.01,
        "floor {floor:.4e} vs 2mg {:.4e}",
        2.0 * mg
    );
    // The top granule presses the bottom one down with its weight (the
    // vertical component: a tilted face normal makes Σ F_n larger).
    let pair = -avg.first_pair_force_z;
    assert!(
        (pair / mg - 1.0).abs() < 0.01,
        "pair {pair:.4e} vs mg {mg:.4e}"
    );
    let c = asm.centre_of_mass(1);
    assert!(
        c[0].hypot(c[1]) < 1e-6,
        "the top granule left the axis: {c:?}"
    );
}

/// A 3×3×3 simple-cubic block of elastic granules in a box, touching
/// everywhere, pressed by the lid and the four sides by 100 µm (3.3 %) and
/// held: the floor and the side walls' friction carry the lid force and
/// the weight, every
/// neighbour pair touches (the centre granule 6 times, coordination
/// number 4). Unpressed, the faceted granules balanced vertex on vertex
/// roll off each other and the lattice sinks (a coarse polyhedron on a
/// vertex is unstable).
#[test]
fn a_simple_cubic_block_in_a_box() {
    let mesh = OwnedReference::sphere(R, MeshLevel::new(4, 1), false).unwrap();
    let mut placed = Vec::new();
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                let c = |n: usize| (n as Real - 1.0) * 2.0 * R;
                placed.push(Placement::at([c(i), c(j), R + c(k) + 2.0 * R]));
            }
        }
    }
    let half = 3.0 * R;
    // Floor fixed; the four sides and the lid press in by 100 µm (3.3 %)
    // at 50 mm/s, then hold.
    let press = |normal: [Real; 3], offset: Real| {
        WallSpec::moving(Wall::Plane(Plane { normal, offset }), 50e-3, 2e-3)
    };
    let walls = vec![
        plane([0.0, 0.0, 1.0], 0.0),
        press([1.0, 0.0, 0.0], -half),
        press([-1.0, 0.0, 0.0], -half),
        press([0.0, 1.0, 0.0], -half),
        press([0.0, -1.0, 0.0], -half),
        press([0.0, 0.0, -1.0], -6.0 * R),
    ];
    let mut asm = Assembly::new(params_of(true), &mesh, &placed, walls).unwrap();
    let weight = 27.0 * asm.granule_mass(0) * G;
    let avg = run(&mut asm, 10e-3, 4e-3);
    let lid_force = avg.wall_normal[5];
    let support = avg.wall_normal[0] + avg.wall_friction_z.iter().sum::<Real>();
    let load = lid_force + weight;
    eprintln!("weight {weight:.4e} lid {lid_force:.4e} support {support:.4e} {avg:?}");
    assert!(
        lid_force > 2.0 * weight,
        "the lid must press: {lid_force:.4e} N"
    );
    assert!(
        (support / load - 1.0).abs() < 0.01,
        "support {support:.4e} vs load {load:.4e}"
    );
    let touching: Vec<usize> = avg.contacts.iter().map(|c| c.round() as usize).collect();
    assert_eq!(touching[13], 6, "centre granule contacts: {touching:?}");
    let z = touching.iter().sum::<usize>() as Real / 27.0;
    assert_eq!(z, 4.0, "coordination number {z}: {touching:?}");
}
