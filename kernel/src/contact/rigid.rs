//! The rigid-mode pre-solve of a granule's wall contacts under selective
//! mass scaling (an addition to physics.md §5.3–§5.5, for the selective
//! mass matrix of `granule::dynamics`). **A building block: the bed does
//! not use it yet** (BENCHMARKS.md, "Selective ×30 and the contacts' rigid
//! coupling", says what was measured and what is missing).
//!
//! Under M' = M'(1 − P) + (M'/F)P a contact force moves its node by its own
//! share f/m' and the whole granule by (F − 1)× the rigid part of it: the
//! rigid modes carry the physical inertia, F× less than the deformational
//! ones. The kinematic contact closes each gap in one step, one constraint
//! at a time; the rigid responses of all the constraints on a granule then
//! add up. The nodes pressed flat by a punch all push the same way, and
//! with the per-node contact masses of
//! `granule::damping::selective_contact_masses` their summed rigid response
//! reopens the gaps every step: at F = 30 the contacts of an 8-granule bed
//! inject energy (contact loss −57 % of the punch work with friction,
//! −623 % without). A bound on the summed response folded into the masses
//! cannot tell such a push from a granule squeezed from both sides, where
//! the responses cancel, and leaves the gaps open instead (the contacts then
//! dissipated 67 % of the punch work).
//!
//! So the granule's rigid displacement u = (translation t, small rotation
//! w) of the step is solved for first, each wall contact held as a spring
//! of its kinematic stiffness m/Δt² to the prescribed wall:
//!
//! u = (F − 1) W Σ_k j_k λ_k Δt²,  λ_k = m_k (c_k − j_k·u)/Δt²,
//!
//! with j_k = (e, r_k × e) a direction e of the contact (r from the centre
//! of mass), c_k the closure it needs along e and W = diag(1/Σm', J'⁻¹) the
//! rigid mobility of the stored masses, i.e.
//!
//! (W⁻¹/(F − 1) + Σ_k m_k j_k j_kᵀ) u = Σ_k m_k c_k j_k,
//!
//! a symmetric positive definite 6×6 system ([`RigidContact::solve`]). The
//! wall forces then close what the rigid displacement leaves, gap + n·u(x)
//! ([`RigidShift::at`], `wall::wall_contact` with `PredictedNodes::rigid_shift`),
//! with the stored masses m'. For a granule touched by walls only this is
//! the exact one-step closure of the bilateral system — frictionless, or
//! with every contact sticking (a contact that slips at the Coulomb cap
//! gets less force than the system assumed) — up to nodes that the rigid
//! motion alone clears (they get no force, and the others are left a
//! little open): `tests/tests/selective_mass.rs`. On the 8-granule bed it
//! gave a contact loss of 1.7 % of the punch work (physical masses 1.6 %).
//!
//! What stops the bed from using it: a granule's pair contacts move it too.
//! Left out of its system, they turned the die's friction around; solved
//! on each side with the other side held, both sides of a pair take up the
//! same gap and the forces stall. One solve over all granules at once
//! (branch `wip/joint-presolve`) fixes both, but the die friction then
//! falls to about zero, where physical masses carry 3 % of the punch force
//! on it: the granule's rigid motion takes up the slip that a stuck node
//! holds against with physical masses. Wall friction under the pre-solve
//! is the open problem.
//!
//! Callers: the contacts of the system and the forces use the stored
//! masses m', those of the frame given to [`RigidContact::new`].

use crate::Real;
use crate::granule::damping::RigidFrame;
use nalgebra::{SMatrix, SVector};

/// A granule's rigid displacement over the step: translation and a small
/// rotation about `centre`, m and rad (zero: none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RigidShift {
    /// Centre of mass the rotation is about, m.
    pub centre: [Real; 3],
    /// Translation t, m.
    pub translation: [Real; 3],
    /// Rotation vector w, rad.
    pub rotation: [Real; 3],
}

impl RigidShift {
    /// No rigid displacement.
    pub const NONE: Self = Self {
        centre: [0.0; 3],
        translation: [0.0; 3],
        rotation: [0.0; 3],
    };

    /// The displacement t + w × (x − centre) of the point `x`, m.
    #[inline]
    pub fn at(&self, x: &[Real; 3]) -> [Real; 3] {
        let r = [
            x[0] - self.centre[0],
            x[1] - self.centre[1],
            x[2] - self.centre[2],
        ];
        let (t, w) = (self.translation, self.rotation);
        [
            t[0] + w[1] * r[2] - w[2] * r[1],
            t[1] + w[2] * r[0] - w[0] * r[2],
            t[2] + w[0] * r[1] - w[1] * r[0],
        ]
    }
}

/// The 6×6 system of one granule's constraints in a sweep (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidContact {
    frame: RigidFrame,
    stiffness: SMatrix<Real, 6, 6>,
    load: SVector<Real, 6>,
}

impl RigidContact {
    /// No constraint yet, for the granule with `frame` (its stored masses
    /// m' at x_n); moments about its centre of mass.
    pub fn new(frame: RigidFrame) -> Self {
        Self {
            frame,
            stiffness: SMatrix::zeros(),
            load: SVector::zeros(),
        }
    }

    /// Adds one constraint at `point` (m) that pushes this granule along
    /// the unit `normal` with stiffness `mass` (kg: the mass its force is
    /// computed with, a wall contact's shared mass m'/n) and needs the
    /// closure `closure` (m, −gap).
    pub fn add(&mut self, point: &[Real; 3], normal: &[Real; 3], mass: Real, closure: Real) {
        let j = self.direction(point, normal);
        for a in 0..6 {
            for b in 0..6 {
                self.stiffness[(a, b)] += mass * j[a] * j[b];
            }
            self.load[a] += mass * closure * j[a];
        }
    }

    /// Adds one sticking contact at `point` (m) with stiffness `mass` (kg)
    /// that needs this granule's point to move by `target` (m): the normal
    /// closure and the cancelling of the tangential slip of the step, one
    /// [`Self::add`] along each axis.
    pub fn add_stick(&mut self, point: &[Real; 3], mass: Real, target: &[Real; 3]) {
        for (a, &t) in target.iter().enumerate() {
            let mut e = [0.0; 3];
            e[a] = 1.0;
            self.add(point, &e, mass, t);
        }
    }

    /// j = (e, r × e) of the unit direction `e` at `point`.
    fn direction(&self, point: &[Real; 3], e: &[Real; 3]) -> SVector<Real, 6> {
        let r = [
            point[0] - self.frame.centre[0],
            point[1] - self.frame.centre[1],
            point[2] - self.frame.centre[2],
        ];
        SVector::<Real, 6>::from([
            e[0],
            e[1],
            e[2],
            r[1] * e[2] - r[2] * e[1],
            r[2] * e[0] - r[0] * e[2],
            r[0] * e[1] - r[1] * e[0],
        ])
    }

    /// Whether no constraint was added.
    pub fn is_empty(&self) -> bool {
        self.stiffness == SMatrix::<Real, 6, 6>::zeros()
    }

    /// The rigid displacement of the granule under selective mass scaling
    /// by `factor` F: [`RigidShift::NONE`] for F ≤ 1 or not finite, for no
    /// constraint, and if the system is not positive definite (a
    /// degenerate frame, NaN).
    pub fn solve(&self, factor: Real) -> RigidShift {
        let frame = &self.frame;
        if !(factor > 1.0 && factor.is_finite()) || self.is_empty() {
            return RigidShift::NONE;
        }
        let mut a = self.stiffness;
        let k = 1.0 / (factor - 1.0);
        for i in 0..3 {
            a[(i, i)] += k * frame.mass;
            for j in 0..3 {
                a[(3 + i, 3 + j)] += k * frame.inertia[(i, j)];
            }
        }
        let Some(chol) = a.cholesky() else {
            return RigidShift::NONE;
        };
        let u = chol.solve(&self.load);
        if u.iter().any(|v| !v.is_finite()) {
            return RigidShift::NONE;
        }
        RigidShift {
            centre: frame.centre,
            translation: [u[0], u[1], u[2]],
            rotation: [u[3], u[4], u[5]],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit point mass at each corner of a cube of side 2 about the
    /// origin: total mass 8, inertia 16 × 1.
    fn cube_frame() -> RigidFrame {
        let mass = [1.0; 8];
        let x: [[Real; 3]; 8] =
            core::array::from_fn(|i| [0, 1, 2].map(|a| if i >> a & 1 == 1 { 1.0 } else { -1.0 }));
        RigidFrame::of(&mass, &x)
    }

    #[test]
    fn one_spring_shares_the_closure_with_the_rigid_mobility() {
        // One contact through the centre along z: a translation only,
        // u = k c / (k + M/(F−1)) for stiffness k and total mass M.
        let frame = cube_frame();
        let (k, c, f) = (2.0, 1e-6, 5.0);
        let mut system = RigidContact::new(frame);
        system.add(&[0.0, 0.0, 1.0], &[0.0, 0.0, 1.0], k, c);
        let u = system.solve(f);
        let want = k * c / (k + frame.mass / (f - 1.0));
        assert!((u.translation[2] - want).abs() < 1e-15 * want.abs().max(1e-30) + 1e-22);
        assert!(
            u.translation[..2]
                .iter()
                .chain(&u.rotation)
                .all(|v| v.abs() < 1e-20)
        );
        assert_eq!(u.at(&[3.0, -2.0, 0.5]), u.translation);
    }

    #[test]
    fn nothing_to_solve_or_bad_numbers_give_no_shift() {
        let frame = cube_frame();
        let mut system = RigidContact::new(frame);
        assert_eq!(system.solve(30.0), RigidShift::NONE);
        system.add(&[0.0, 0.0, 1.0], &[0.0, 0.0, 1.0], 1.0, 1e-6);
        for f in [1.0, 0.5, Real::NAN, Real::INFINITY] {
            assert_eq!(system.solve(f), RigidShift::NONE, "F {f}");
        }
        let mut bad = RigidContact::new(frame);
        bad.add(&[0.0, 0.0, 1.0], &[0.0, 0.0, 1.0], Real::NAN, 1e-6);
        assert_eq!(bad.solve(30.0), RigidShift::NONE);
        let mut degenerate = RigidContact::new(RigidFrame::default());
        degenerate.add(&[0.0, 0.0, 1.0], &[0.0, 0.0, 1.0], 1.0, 1e-6);
        assert_eq!(degenerate.solve(30.0), RigidShift::NONE);
    }
}
