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
use crate::contact::quad::sub;
use crate::tensor::{Mat3, det_mat, inverse_with_det, smallest_eigenvalue};

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
    /// Total mass Σ m_I of the nodes, kg.
    pub mass: Real,
    /// Angular momentum about the centre of mass L = Σ m_I r_I × (v_I − v_c),
    /// kg m²/s (J_c ω when J_c is invertible), summed as
    /// Σ m_I r_I × v_I ([`RigidFrame::motion`]).
    pub angular_momentum: [Real; 3],
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

    /// Σ m_I |P v_I|² = m |v_c|² + ω·L: twice the kinetic energy of the
    /// rigid part of the motion, J.
    pub fn twice_kinetic_energy(&self) -> Real {
        let (v, w, l) = (self.velocity, self.omega, self.angular_momentum);
        self.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
            + (w[0] * l[0] + w[1] * l[1] + w[2] * l[2])
    }

    /// No motion at all (the projection when the rigid modes are held).
    pub const REST: RigidMotion = RigidMotion {
        centre: [0.0; 3],
        velocity: [0.0; 3],
        omega: [0.0; 3],
        mass: 0.0,
        angular_momentum: [0.0; 3],
    };
}

/// The mass-orthogonal projection of velocities `v` onto the six rigid modes
/// of nodes at `x` with masses `mass` (kg). All slices have one entry per
/// node; a node `v` lacks counts as a NaN velocity (a NaN motion, not a
/// panic).
pub fn rigid_motion(mass: &[Real], x: &[[Real; 3]], v: &[[Real; 3]]) -> RigidMotion {
    rigid_motion_of(mass, x, velocity_of(v))
}

/// Node `i`'s velocity of `v`, NaN for a node past it.
fn velocity_of(v: &[[Real; 3]]) -> impl Fn(usize) -> [Real; 3] + '_ {
    |i| v.get(i).copied().unwrap_or([Real::NAN; 3])
}

/// [`rigid_motion`] of the velocity field `v(I)` given node by node (for a
/// field the caller has not stored, such as M⁻¹f).
pub fn rigid_motion_of(
    mass: &[Real],
    x: &[[Real; 3]],
    v: impl Fn(usize) -> [Real; 3],
) -> RigidMotion {
    RigidFrame::of(mass, x).motion(mass, x, v)
}

/// ω = J⁻¹L (rad/s, or its rate for a torque), or zero if J is singular.
fn spin(inertia: &Mat3, l: &[Real; 3]) -> [Real; 3] {
    let det = det_mat(inertia);
    if det > 0.0 {
        let inv = inverse_with_det(inertia, det);
        [0, 1, 2].map(|a| inv[(a, 0)] * l[0] + inv[(a, 1)] * l[1] + inv[(a, 2)] * l[2])
    } else {
        [0.0; 3]
    }
}

/// What ½ Σ m'|v|² overcounts of the kinetic energy ½ v·M'v under selective
/// mass scaling by `factor` (`dynamics` module docs): ½ (1 − 1/F) Σ m'|Pv|²,
/// J, for nodes at `x` with stored masses `mass` and velocities `v`.
pub fn selective_kinetic_excess(
    mass: &[Real],
    x: &[[Real; 3]],
    v: &[[Real; 3]],
    factor: Real,
) -> Real {
    selective_excess_of(&rigid_motion(mass, x, v), factor)
}

/// ½ (1 − 1/F) Σ m'|Pv|² from the rigid `motion` Pv ([`RigidFrame::motion`]
/// of the velocities), J: [`selective_kinetic_excess`] for a caller that
/// has the motion.
pub fn selective_excess_of(motion: &RigidMotion, factor: Real) -> Real {
    0.5 * (1.0 - 1.0 / factor) * motion.twice_kinetic_energy()
}

/// The sums Σ m_I, Σ m_I x_I and Σ m_I v_I of a granule's nodes, added node
/// by node in node order: the first passes of [`RigidFrame::of`] and of
/// [`RigidFrame::motion`], for a caller whose own node loop produces x and
/// v (the corrector), so that [`MomentSums::frame_and_motion`] needs one
/// more pass instead of four. The same bits as those two functions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MomentSums {
    /// Σ m_I, kg.
    mass: Real,
    /// Σ m_I x_I, kg m.
    mx: [Real; 3],
    /// Σ m_I v_I, kg m/s.
    mv: [Real; 3],
}

impl MomentSums {
    /// Adds node mass `m` (kg) at `x` (m) with velocity `v` (m/s).
    #[inline(always)]
    pub fn add(&mut self, m: Real, x: &[Real; 3], v: &[Real; 3]) {
        self.mass += m;
        for a in 0..3 {
            self.mx[a] += m * x[a];
            self.mv[a] += m * v[a];
        }
    }

    /// The frame of the nodes `mass`, `x` and the rigid motion of their
    /// velocities `v` — the bits of `RigidFrame::of(mass, x)` and of its
    /// `motion(mass, x, |i| v[i])` — when `self` holds exactly the sums of
    /// these nodes ([`MomentSums::add`] in node order). One pass for the
    /// inertia and the angular momentum.
    pub fn frame_and_motion(
        &self,
        mass: &[Real],
        x: &[[Real; 3]],
        v: &[[Real; 3]],
    ) -> (RigidFrame, RigidMotion) {
        let m = self.mass;
        let centre = self.mx.map(|s| s / m);
        let velocity = self.mv.map(|s| s / m);
        let mut inertia = InertiaSum::default();
        let mut l = [0.0; 3];
        for ((mi, xi), vi) in mass.iter().zip(x).zip(v) {
            let r = sub(xi, &centre);
            inertia.add(*mi, &r);
            add_angular_momentum(&mut l, *mi, &r, vi);
        }
        let frame = RigidFrame {
            mass: m,
            centre,
            inertia: inertia.tensor(),
        };
        let motion = frame.motion_from_sums(velocity, l);
        (frame, motion)
    }
}

/// l += m r × u: one node's angular momentum about the centre (r its
/// offset, u its velocity).
#[inline(always)]
fn add_angular_momentum(l: &mut [Real; 3], m: Real, r: &[Real; 3], u: &[Real; 3]) {
    l[0] += m * (r[1] * u[2] - r[2] * u[1]);
    l[1] += m * (r[2] * u[0] - r[0] * u[2]);
    l[2] += m * (r[0] * u[1] - r[1] * u[0]);
}

/// The six distinct entries of a symmetric inertia tensor being summed:
/// `[xx, yy, zz, xy, xz, yz]`, kg m².
#[derive(Clone, Copy, Default)]
struct InertiaSum([Real; 6]);

impl InertiaSum {
    /// Adds the inertia m (|r|²1 − r⊗r) of a point mass `m` at `r` from
    /// the centre. An off-diagonal entry is m (0 − r_a r_b), and r_a r_b =
    /// r_b r_a exactly, so the mirrored entry of a full 3×3 sum would hold
    /// the same bits: summing six entries instead of nine changes none.
    #[inline]
    fn add(&mut self, m: Real, r: &[Real; 3]) {
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        let s = &mut self.0;
        s[0] += m * (r2 - r[0] * r[0]);
        s[1] += m * (r2 - r[1] * r[1]);
        s[2] += m * (r2 - r[2] * r[2]);
        s[3] += m * (0.0 - r[0] * r[1]);
        s[4] += m * (0.0 - r[0] * r[2]);
        s[5] += m * (0.0 - r[1] * r[2]);
    }

    /// The full tensor.
    fn tensor(&self) -> Mat3 {
        let [xx, yy, zz, xy, xz, yz] = self.0;
        Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
    }
}

/// A granule's total mass, centre of mass and inertia about it: what the
/// rigid response to a set of forces needs (default: all zero).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RigidFrame {
    /// Σ m_I, kg.
    pub mass: Real,
    /// Centre of mass x_c, m.
    pub centre: [Real; 3],
    /// J_c = Σ m_I (|r_I|²1 − r_I⊗r_I), kg m².
    pub inertia: Mat3,
}

impl RigidFrame {
    /// The frame of nodes at `x` with masses `mass` (kg).
    pub fn of(mass: &[Real], x: &[[Real; 3]]) -> Self {
        let mut m = 0.0;
        let mut mx = [0.0; 3];
        for (mi, xi) in mass.iter().zip(x) {
            m += mi;
            for a in 0..3 {
                mx[a] += mi * xi[a];
            }
        }
        let centre = mx.map(|s| s / m);
        let mut inertia = InertiaSum::default();
        for (mi, xi) in mass.iter().zip(x) {
            inertia.add(*mi, &sub(xi, &centre));
        }
        Self {
            mass: m,
            centre,
            inertia: inertia.tensor(),
        }
    }

    /// The mass-orthogonal projection of the velocity field `v(I)` onto
    /// the six rigid modes: the velocity of the centre of mass and the
    /// angular velocity J_c⁻¹ L, with L = Σ m_I r_I × (v_I − v_c).
    ///
    /// `self` must be the frame of these `mass` and `x`
    /// ([`RigidFrame::of`]); a caller that needs several projections at
    /// one configuration (damping, predictor and corrector of a step) takes
    /// the frame once. One pass over the nodes, `v` called once per node:
    /// L is summed as Σ m r × v, which is Σ m r × (v − v_c) because
    /// Σ m r = 0 about the centre of mass (but for the rounding of the
    /// centre, of the order of the rounding of r = x − x_c that either
    /// form has), so v_c is not needed inside the loop. A node whose
    /// velocity is exactly zero adds nothing and is skipped (most nodes of
    /// a contact increment): the sums start at +0 and adding ±0 leaves any
    /// of them unchanged, so the bits are those of the full sum. The sums
    /// run in node order, so the result has the bits of [`rigid_motion_of`]
    /// whether the frame was taken once or each time.
    pub fn motion(
        &self,
        mass: &[Real],
        x: &[[Real; 3]],
        v: impl Fn(usize) -> [Real; 3],
    ) -> RigidMotion {
        let mut mv = [0.0; 3];
        let mut l = [0.0; 3];
        for (i, (mi, xi)) in mass.iter().zip(x).enumerate() {
            let vi = v(i);
            if vi == [0.0; 3] {
                continue;
            }
            for a in 0..3 {
                mv[a] += mi * vi[a];
            }
            add_angular_momentum(&mut l, *mi, &sub(xi, &self.centre), &vi);
        }
        self.motion_from_sums(mv.map(|s| s / self.mass), l)
    }

    /// The motion of centre velocity `velocity` and angular momentum `l`
    /// about the centre.
    fn motion_from_sums(&self, velocity: [Real; 3], l: [Real; 3]) -> RigidMotion {
        RigidMotion {
            centre: self.centre,
            velocity,
            omega: spin(&self.inertia, &l),
            mass: self.mass,
            angular_momentum: l,
        }
    }

    /// The rigid motion the forces `f` at the points `x` (N, m; pairs)
    /// give per unit time: velocity ΣF/m and ω = J_c⁻¹ Σ r × f, i.e. P(M⁻¹f)
    /// for nodal forces (zero ω if J_c is singular). Its
    /// `angular_momentum` holds the torque Σ r × f (a rate, N m), so
    /// [`RigidMotion::twice_kinetic_energy`] means nothing for it.
    pub fn response(&self, forces: impl Iterator<Item = ([Real; 3], [Real; 3])>) -> RigidMotion {
        let (mut total, mut torque) = ([0.0; 3], [0.0; 3]);
        for (x, f) in forces {
            let r = sub(&x, &self.centre);
            for a in 0..3 {
                total[a] += f[a];
            }
            torque[0] += r[1] * f[2] - r[2] * f[1];
            torque[1] += r[2] * f[0] - r[0] * f[2];
            torque[2] += r[0] * f[1] - r[1] * f[0];
        }
        let omega = spin(&self.inertia, &torque);
        RigidMotion {
            centre: self.centre,
            velocity: total.map(|t| t / self.mass),
            omega,
            mass: self.mass,
            angular_momentum: torque,
        }
    }
}

/// The nodal masses the kinematic contact sees under selective mass scaling
/// by `factor` F (`dynamics` module docs), kg, written to `out`, for nodes
/// at `x` with stored masses `mass` (F × physical) and their `frame`.
///
/// Through M'⁻¹ = (1/m')(1 + (F−1)P) a contact force on node I moves it by
/// its own share and by its share of the granule's rigid response, which the
/// contact's one-step gap closure (force = gap × mass / Δt²) must include
/// or it overshoots: with F comparable to the node count the overshoot
/// exceeds 2 and the contact diverges. P_II's largest eigenvalue is at most
/// p_I = m'_I (1/Σm' + |r_I|²/λ_min(J'_c)) (translation plus rotation about
/// the centre of mass; exact for a sphere's inertia), and at most 1; the
/// contact mass m'_I / (1 + (F−1) p_I) does not overshoot for a node alone.
/// The rigid response to the other nodes' forces is the caller's to predict
/// ([`RigidFrame::response`]). F ≤ 1 (or not finite): the stored masses.
/// Returns false, writing nothing, if the slices differ in length.
#[must_use]
pub fn selective_contact_masses(
    frame: &RigidFrame,
    mass: &[Real],
    x: &[[Real; 3]],
    factor: Real,
    out: &mut [Real],
) -> bool {
    if out.len() != mass.len() || x.len() != mass.len() {
        return false;
    }
    if !(factor > 1.0 && factor.is_finite()) {
        out.copy_from_slice(mass);
        return true;
    }
    // A hair below λ_min: near a repeated root the closed form's acos may
    // overestimate it by ~1e-8 relative, which would under-bound p_I.
    let lambda = smallest_eigenvalue(&frame.inertia) * (1.0 - 1e-6);
    let valid = lambda > 0.0 && frame.mass > 0.0;
    for ((o, mi), xi) in out.iter_mut().zip(mass).zip(x) {
        let r = sub(xi, &frame.centre);
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        let p = mi * (1.0 / frame.mass + r2 / lambda);
        // A degenerate body (λ_min ≤ 0, NaN): the bound P_II ≤ 1.
        let p = if valid && p < 1.0 { p } else { 1.0 };
        *o = mi / (1.0 + (factor - 1.0) * p);
    }
    true
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
    let frame = rigid_modes.then(|| RigidFrame::of(mass, x));
    damping_forces_in(frame.as_ref(), mass, x, v, c, f_d);
}

/// [`damping_forces`] with the nodes' [`RigidFrame`] taken by the caller
/// (`None`: the rigid modes are held, P = 0); the same bits.
pub fn damping_forces_in(
    frame: Option<&RigidFrame>,
    mass: &[Real],
    x: &[[Real; 3]],
    v: &[[Real; 3]],
    c: Real,
    f_d: &mut [[Real; 3]],
) {
    let rigid = match frame {
        Some(frame) => frame.motion(mass, x, velocity_of(v)),
        None => RigidMotion::REST,
    };
    damping_forces_of(&rigid, mass, x, v, c, f_d);
}

/// [`damping_forces_in`] with the rigid part of `v` taken by the caller:
/// `rigid` is the frame's `motion(mass, x, |i| v[i])`, or
/// [`RigidMotion::REST`] when the rigid modes are held; the same bits.
/// Entries of `f_d` past the shortest of `mass`, `x` and `v` are NaN (they
/// kept stale forces).
pub fn damping_forces_of(
    rigid: &RigidMotion,
    mass: &[Real],
    x: &[[Real; 3]],
    v: &[[Real; 3]],
    c: Real,
    f_d: &mut [[Real; 3]],
) {
    for (((m, xi), vi), fi) in mass.iter().zip(x).zip(v).zip(f_d.iter_mut()) {
        let r = rigid.velocity_at(xi);
        for a in 0..3 {
            fi[a] = -c * m * (vi[a] - r[a]);
        }
    }
    let nodes = mass.len().min(x.len()).min(v.len());
    for fi in f_d.iter_mut().skip(nodes) {
        *fi = [Real::NAN; 3];
    }
}

/// Damping coefficient c = 2ξω₁ with ω₁ ≈ 2.5 c_s/R, the lowest
/// deformational frequency of a free elastic sphere (physics.md §4.4), 1/s.
pub fn damping_coefficient(ratio: Real, shear_modulus: Real, density: Real, radius: Real) -> Real {
    2.0 * ratio * 2.5 * crate::math::sqrt(shear_modulus / density) / radius
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Random masses and points (the kernel has no allocator, even here).
    const N: usize = 500;

    fn cloud(seed: u64) -> ([Real; N], [[Real; 3]; N]) {
        let mut rng = Rng::new(seed);
        let mass = core::array::from_fn(|_| rng.uniform(1e-10, 3e-10));
        let x = core::array::from_fn(|_| core::array::from_fn(|_| rng.uniform(-5e-4, 6e-4)));
        (mass, x)
    }

    /// Velocities shorter than the masses and positions give a NaN motion
    /// and NaN damping forces past them, not an index panic or stale forces
    /// (the kernel API review of session 55).
    #[test]
    fn short_velocities_are_nan_not_a_panic() {
        let (mass, x) = cloud(3);
        let v = [[1e-3, 0.0, 0.0]; N];
        let short = &v[..N / 2];
        assert!(rigid_motion(&mass, &x, short).velocity[0].is_nan());
        assert!(selective_kinetic_excess(&mass, &x, short, 10.0).is_nan());
        for rigid_modes in [true, false] {
            let mut f_d = [[7.0; 3]; N];
            damping_forces(&mass, &x, short, 5.0, rigid_modes, &mut f_d);
            assert!(f_d[N / 2..].iter().flatten().all(|f| f.is_nan()));
            if !rigid_modes {
                assert!(f_d[..N / 2].iter().flatten().all(|f| f.is_finite()));
            }
        }
    }

    /// The six-entry sum of the frame gives the bits of the full nine-entry
    /// sum Σ m (|r|²1 − r⊗r) (the symmetry argument of `InertiaSum::add`).
    #[test]
    fn six_entry_inertia_has_the_bits_of_the_full_sum() {
        for seed in 1..20 {
            let (mass, x) = cloud(seed);
            let frame = RigidFrame::of(&mass, &x);
            let mut full = Mat3::zeros();
            for (m, p) in mass.iter().zip(&x) {
                let r = sub(p, &frame.centre);
                let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                for a in 0..3 {
                    for b in 0..3 {
                        full[(a, b)] += m * (if a == b { r2 } else { 0.0 } - r[a] * r[b]);
                    }
                }
            }
            for (got, want) in frame.inertia.iter().zip(full.iter()) {
                assert_eq!(got.to_bits(), want.to_bits(), "seed {seed}");
            }
        }
    }

    /// A rigid velocity field v_c + ω × (x − x_c) projects onto itself.
    #[test]
    fn motion_recovers_a_rigid_field() {
        let (mass, x) = cloud(7);
        let frame = RigidFrame::of(&mass, &x);
        let (vc, omega) = ([0.01, -0.02, 0.005], [30.0, -12.0, 7.0]);
        let field = RigidMotion {
            centre: frame.centre,
            velocity: vc,
            omega,
            ..RigidMotion::REST
        };
        let got = frame.motion(&mass, &x, |i| field.velocity_at(&x[i]));
        for a in 0..3 {
            assert!(
                (got.velocity[a] - vc[a]).abs() < 1e-14,
                "{:?}",
                got.velocity
            );
            assert!((got.omega[a] - omega[a]).abs() < 1e-11, "{:?}", got.omega);
        }
    }

    /// The textbook projection in one function (centre and mass-weighted
    /// velocity in one pass, L = Σ m r × (v − v_c) and the full inertia in
    /// the second): the reference, to round-off, for the one-pass motion.
    fn textbook_projection(mass: &[Real], x: &[[Real; 3]], v: &[[Real; 3]]) -> RigidMotion {
        let (mut m, mut mx, mut mv) = (0.0, [0.0; 3], [0.0; 3]);
        for ((mi, xi), vi) in mass.iter().zip(x).zip(v) {
            m += mi;
            for a in 0..3 {
                mx[a] += mi * xi[a];
                mv[a] += mi * vi[a];
            }
        }
        let (centre, velocity) = (mx.map(|s| s / m), mv.map(|s| s / m));
        let (mut l, mut inertia) = ([0.0; 3], Mat3::zeros());
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
        RigidMotion {
            centre,
            velocity,
            omega: spin(&inertia, &l),
            mass: m,
            angular_momentum: l,
        }
    }

    /// The one-pass motion (L summed as Σ m r × v) agrees with
    /// the textbook projection to round-off on random clouds and fields,
    /// also where a large common translation makes v ≫ v − v_c. The bound
    /// is that of the cancellation in Σ m r × v: a few ulp of
    /// Σ m |r| |v| (an error in the formula, e.g. the moment taken about
    /// the origin or a lost node, would not pass).
    #[test]
    fn the_one_pass_motion_is_the_textbook_projection() {
        for seed in 1..20 {
            let (mass, x) = cloud(seed);
            for drift in [0.0, 10.0] {
                let mut v = velocities(seed + 100);
                for vi in &mut v {
                    vi[0] += drift;
                }
                let want = textbook_projection(&mass, &x, &v);
                let got = rigid_motion(&mass, &x, &v);
                let frame = RigidFrame::of(&mass, &x);
                let scale: Real = mass
                    .iter()
                    .zip(&x)
                    .zip(&v)
                    .map(|((m, xi), vi)| {
                        let r = sub(xi, &frame.centre);
                        m * norm3(&r) * norm3(vi)
                    })
                    .sum();
                for a in 0..3 {
                    assert_eq!(got.velocity[a].to_bits(), want.velocity[a].to_bits());
                    let dl = (got.angular_momentum[a] - want.angular_momentum[a]).abs();
                    assert!(dl <= 64.0 * Real::EPSILON * scale, "seed {seed}: ΔL {dl:e}");
                }
            }
        }
    }

    fn norm3(a: &[Real; 3]) -> Real {
        (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
    }

    /// A random velocity field on the cloud's nodes, m/s.
    fn velocities(seed: u64) -> [[Real; 3]; N] {
        let mut rng = Rng::new(seed);
        core::array::from_fn(|_| core::array::from_fn(|_| rng.uniform(-0.1, 0.1)))
    }

    /// Every field of a rigid motion, as bits.
    fn motion_bits(r: &RigidMotion) -> [u64; 13] {
        let mut out = [r.mass.to_bits(); 13];
        let all = r.centre.iter().chain(&r.velocity).chain(&r.omega);
        for (o, c) in out[1..].iter_mut().zip(all.chain(&r.angular_momentum)) {
            *o = c.to_bits();
        }
        out
    }

    /// The sums added node by node and one more pass give the frame and
    /// the motion of `RigidFrame::of` and `motion`, to the bit.
    #[test]
    fn moment_sums_give_the_frame_and_motion_of_the_separate_passes() {
        for seed in 1..40 {
            let (mass, x) = cloud(seed);
            let mut v = velocities(seed + 200);
            if seed >= 20 {
                // A contact-like field: most nodes exactly at rest (some at
                // −0), which `motion` skips and `frame_and_motion` adds.
                for (i, vi) in v.iter_mut().enumerate() {
                    if i % 7 != 0 {
                        *vi = if i % 3 == 0 { [-0.0; 3] } else { [0.0; 3] };
                    }
                }
            }
            let mut sums = MomentSums::default();
            for ((m, xi), vi) in mass.iter().zip(&x).zip(&v) {
                sums.add(*m, xi, vi);
            }
            let (frame, motion) = sums.frame_and_motion(&mass, &x, &v);
            let want_frame = RigidFrame::of(&mass, &x);
            let want_motion = want_frame.motion(&mass, &x, |i| v[i]);
            let frame_bits = |f: &RigidFrame| {
                let mut out = [f.mass.to_bits(); 13];
                for (o, c) in out[1..]
                    .iter_mut()
                    .zip(f.centre.iter().chain(f.inertia.iter()))
                {
                    *o = c.to_bits();
                }
                out
            };
            assert_eq!(frame_bits(&frame), frame_bits(&want_frame), "seed {seed}");
            assert_eq!(
                motion_bits(&motion),
                motion_bits(&want_motion),
                "seed {seed}"
            );
            assert_eq!(
                selective_excess_of(&motion, 20.0).to_bits(),
                selective_kinetic_excess(&mass, &x, &v, 20.0).to_bits()
            );
        }
    }
}
