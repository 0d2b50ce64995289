//! Selective mass-proportional damping of the non-rigid part of a granule's
//! velocity (physics.md §4.4): the rigid translation and spin are removed by
//! the mass-orthogonal projection P first and left undamped.
//!
//! **Deviation from physics.md §4.4 (a choice):** the damping force is the
//! lagged one, f_d = −c M (1 − P) v_{n−½} (stable for cΔt < 2; here
//! cΔt ≈ 0.12 for ξ = 0.5, and mass scaling leaves cΔt unchanged), not the
//! semi-implicit form on the undamped update v*. With kinematic contact, v*
//! of a node in contact still carries the elastic rebound that the contact
//! correction removes a moment later; damping it made the damping work
//! negative (−4.8 % of the platen work for B2) and the platen force depend
//! on Δt (+1.7 % when Δt was halved). The lagged force acts on the motion
//! that actually happened.

use crate::Real;
use crate::tensor::{Mat3, det_mat, inverse_with_det};

/// Rigid-body motion of a set of nodes: centre of mass, its velocity and
/// the angular velocity ω = J_c⁻¹ L.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidMotion {
    /// Centre of mass x_c, m.
    pub centre: [Real; 3],
    /// Velocity of the centre of mass, m/s.
    pub velocity: [Real; 3],
    /// Angular velocity, rad/s.
    pub omega: [Real; 3],
}

impl RigidMotion {
    /// The rigid velocity v_c + ω × (x − x_c) at position `x`.
    #[inline]
    pub fn velocity_at(&self, x: &[Real; 3]) -> [Real; 3] {
        let r = [
            x[0] - self.centre[0],
            x[1] - self.centre[1],
            x[2] - self.centre[2],
        ];
        let w = self.omega;
        [
            self.velocity[0] + w[1] * r[2] - w[2] * r[1],
            self.velocity[1] + w[2] * r[0] - w[0] * r[2],
            self.velocity[2] + w[0] * r[1] - w[1] * r[0],
        ]
    }
}

/// The mass-orthogonal projection of velocities `v` onto the six rigid modes
/// of nodes at `x` with masses `mass` (kg). All slices have one entry per node.
pub fn rigid_motion(mass: &[Real], x: &[[Real; 3]], v: &[[Real; 3]]) -> RigidMotion {
    let mut m = 0.0;
    let mut mx = [0.0; 3];
    let mut mv = [0.0; 3];
    for ((mi, xi), vi) in mass.iter().zip(x).zip(v) {
        m += mi;
        for a in 0..3 {
            mx[a] += mi * xi[a];
            mv[a] += mi * vi[a];
        }
    }
    let centre = mx.map(|s| s / m);
    let velocity = mv.map(|s| s / m);
    let mut l = [0.0; 3];
    let mut inertia = Mat3::zeros();
    for ((mi, xi), vi) in mass.iter().zip(x).zip(v) {
        let r = [xi[0] - centre[0], xi[1] - centre[1], xi[2] - centre[2]];
        let u = [
            vi[0] - velocity[0],
            vi[1] - velocity[1],
            vi[2] - velocity[2],
        ];
        l[0] += mi * (r[1] * u[2] - r[2] * u[1]);
        l[1] += mi * (r[2] * u[0] - r[0] * u[2]);
        l[2] += mi * (r[0] * u[1] - r[1] * u[0]);
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        for a in 0..3 {
            for b in 0..3 {
                inertia[(a, b)] += mi * (if a == b { r2 } else { 0.0 } - r[a] * r[b]);
            }
        }
    }
    let det = det_mat(&inertia);
    let omega = if det > 0.0 {
        let inv = inverse_with_det(&inertia, det);
        [0, 1, 2].map(|a| inv[(a, 0)] * l[0] + inv[(a, 1)] * l[1] + inv[(a, 2)] * l[2])
    } else {
        [0.0; 3]
    };
    RigidMotion {
        centre,
        velocity,
        omega,
    }
}

/// Writes the selective damping forces f_d,I = −c m_I w_I into `f_d` (N),
/// where w = v − P v is the deformational part of the velocities `v` (m/s)
/// of nodes at `x` (m) with masses `mass` (kg). `c` is the damping
/// coefficient (1/s). With `rigid_modes` false (symmetry planes fix every
/// rigid mode) P = 0 and the whole velocity is damped.
///
/// The forces sum to zero with zero moment about the centre of mass.
pub fn damping_forces(
    mass: &[Real],
    x: &[[Real; 3]],
    v: &[[Real; 3]],
    c: Real,
    rigid_modes: bool,
    f_d: &mut [[Real; 3]],
) {
    let rigid = if rigid_modes {
        rigid_motion(mass, x, v)
    } else {
        RigidMotion {
            centre: [0.0; 3],
            velocity: [0.0; 3],
            omega: [0.0; 3],
        }
    };
    for (((m, xi), vi), fi) in mass.iter().zip(x).zip(v).zip(f_d.iter_mut()) {
        let r = rigid.velocity_at(xi);
        for a in 0..3 {
            fi[a] = -c * m * (vi[a] - r[a]);
        }
    }
}

/// Damping coefficient c = 2ξω₁ with ω₁ ≈ 2.5 c_s/R, the lowest
/// deformational frequency of a free elastic sphere (physics.md §4.4), 1/s.
pub fn damping_coefficient(ratio: Real, shear_modulus: Real, density: Real, radius: Real) -> Real {
    2.0 * ratio * 2.5 * crate::math::sqrt(shear_modulus / density) / radius
}
