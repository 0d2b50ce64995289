//! The wall pass's virial Σ x ⊗ f (`WallForce::virial`): the sum over the
//! nodes of their predicted positions times the forces the pass put on
//! them. For the die (a cylinder about the z axis) the normal forces point
//! at the axis, so their lateral share Σ (x f_x + y f_y) is −r F_n for
//! nodes at radius r, and friction (axial or around the axis) adds none;
//! for a punch (a plane z = const) the axial share Σ z f_z is z times the
//! axial force.

use granbed_kernel::Real;
use granbed_kernel::contact::rigid::RigidShift;
use granbed_kernel::contact::wall::{Plane, PredictedNodes, Wall, wall_contact};

/// Σ x ⊗ f over the nodes, from the forces `f_c` the pass added to zero.
fn virial_of(x: &[[Real; 3]], f_c: &[[Real; 3]]) -> [[Real; 3]; 3] {
    let mut v = [[0.0; 3]; 3];
    for (x, f) in x.iter().zip(f_c) {
        for (row, x) in v.iter_mut().zip(x) {
            for (v, f) in row.iter_mut().zip(f) {
                *v += x * f;
            }
        }
    }
    v
}

fn close(a: Real, b: Real, scale: Real) -> bool {
    (a - b).abs() <= 1e-12 * scale
}

/// Every component of `got` equals `want` to 10⁻¹² of `scale`.
fn same(got: &[[Real; 3]; 3], want: &[[Real; 3]; 3], scale: Real) {
    for (g, w) in got.iter().flatten().zip(want.iter().flatten()) {
        assert!(close(*g, *w, scale), "{got:?} against {want:?}");
    }
}

#[test]
fn the_virial_is_the_sum_of_position_times_force() {
    let (radius, r) = (1e-3, 1.000_001e-3);
    // Four nodes 1 nm outside the die at different angles and heights,
    // each moved over the step along the axis and around it, so that
    // friction acts (μ = 0.3: some stick, some slip).
    let angles: [Real; 4] = [0.0, 2.0, 3.5, 5.0];
    let x_pred: Vec<[Real; 3]> = angles
        .iter()
        .enumerate()
        .map(|(i, a)| [r * a.cos(), r * a.sin(), 1e-4 * i as Real])
        .collect();
    let x_n: Vec<[Real; 3]> = x_pred
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let s = 1e-9 * (i as Real + 1.0);
            [x[0] + s * x[1] / r, x[1] - s * x[0] / r, x[2] - 3.0 * s]
        })
        .collect();
    let mass = [1e-9, 2e-9, 1.5e-9, 0.5e-9];
    let body = PredictedNodes {
        mass: &mass,
        x_n: &x_n,
        x_pred: &x_pred,
        rigid_shift: RigidShift::NONE,
    };
    let die = Wall::Die { radius };
    let mut f_c = vec![[0.0; 3]; 4];
    let w = wall_contact(&die, 0.3, 1e-14, 0..4, &body, &[], &mut f_c).unwrap();
    assert_eq!(w.contacts, 4);
    let scale = r * f_c.iter().flatten().map(|f| f.abs()).sum::<Real>();
    same(&w.virial, &virial_of(&x_pred, &f_c), scale);
    // Friction acted, yet the lateral share is the normal forces' alone.
    assert!(
        w.tangential.iter().any(|t| t.abs() > 1e-3 * w.normal),
        "{w:?}"
    );
    let lateral = w.virial[0][0] + w.virial[1][1];
    assert!(
        close(lateral, -r * w.normal, scale),
        "{lateral} {}",
        -r * w.normal
    );

    // The upper punch z = h (inward normal −z) with the nodes 1 nm above
    // its face: Σ z f_z = z F_z.
    let h = 2e-4;
    let top: Vec<[Real; 3]> = x_pred.iter().map(|x| [x[0], x[1], h + 1e-9]).collect();
    let body = PredictedNodes {
        x_pred: &top,
        ..body
    };
    let punch = Wall::Plane(Plane {
        normal: [0.0, 0.0, -1.0],
        offset: -h,
    });
    let mut f_c = vec![[0.0; 3]; 4];
    let w = wall_contact(&punch, 0.3, 1e-14, 0..4, &body, &[], &mut f_c).unwrap();
    assert_eq!(w.contacts, 4);
    let fz: Real = f_c.iter().map(|f| f[2]).sum();
    let scale = h * f_c.iter().flatten().map(|f| f.abs()).sum::<Real>();
    assert!(close(w.virial[2][2], (h + 1e-9) * fz, scale), "{w:?}");
    same(&w.virial, &virial_of(&top, &f_c), scale);
}
