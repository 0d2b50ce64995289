//! Node-to-quad projection and the kinematic contact force of one
//! node-to-face constraint (physics.md §5.2–§5.4).

use granbed_kernel::contact::pair::{ContactError, NodeFace, node_face_force};
use granbed_kernel::contact::quad::project;

use crate::buffers::{input, one, one_mut, status};
use crate::status::{
    GRANBED_ERR_DEGENERATE, GRANBED_ERR_INVALID_ARGUMENT, GRANBED_ERR_NON_FINITE, GRANBED_OK,
};

/// Tolerance on |ξ|, |η| of the inside-the-face test (physics.md: 1e-6).
pub const GRANBED_INSIDE_TOLERANCE: f64 = 1e-6;

/// Where a point projects on a bilinear quad.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedQuadProjection {
    /// Local coordinate ξ* of the closest point on the bilinear surface
    /// extended beyond the face (the face is [−1, 1]²): not clamped, so a
    /// point beside the face gives |ξ*| > 1 and `inside` = 0, and its
    /// weights then lie outside [0, 1], which `granbed_node_face_force`
    /// refuses. Which face or edge such a node is held against is the
    /// host's choice.
    pub xi: f64,
    /// Local coordinate η*.
    pub eta: f64,
    /// The closest point x(ξ*, η*), m.
    pub point: [f64; 3],
    /// Unit outward normal x_ξ × x_η / |…| there.
    pub normal: [f64; 3],
    /// Signed gap n·(p − x(ξ*, η*)), m; negative = behind the face.
    pub gap: f64,
    /// Bilinear weights of the four corners at (ξ*, η*).
    pub weights: [f64; 4],
    /// 1 if |ξ*|, |η*| ≤ 1 + `GRANBED_INSIDE_TOLERANCE`, else 0.
    pub inside: i32,
}

/// Projects the point `p` (3 doubles, m) on the bilinear quad `quad`
/// (4 corners × xyz = 12 doubles, counter-clockwise seen from outside, so
/// the normal points out) by Newton's method on the closest-point problem.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_NON_FINITE`, or
/// `GRANBED_ERR_DEGENERATE` (zero-length edge vectors or zero normal, or
/// finite corners so far apart that the normal's length overflows).
///
/// # Safety
/// `p` points to 3 doubles, `quad` to 12, `out` to a writable
/// `GranbedQuadProjection` (or they are NULL: an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_project_node_on_quad(
    p: *const f64,
    quad: *const f64,
    out: *mut GranbedQuadProjection,
) -> i32 {
    status((|| {
        // SAFETY (all three): the caller's contract.
        let p = unsafe { input(p, 1, 3) }?;
        let quad = unsafe { input(quad, 1, 12) }?;
        let out = unsafe { one_mut(out) }?;
        let (&[p], _) = p.as_chunks::<3>() else {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        };
        let (&[c0, c1, c2, c3], _) = quad.as_chunks::<3>() else {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        };
        if !p.iter().chain(quad.iter()).all(|v| v.is_finite()) {
            return Err(GRANBED_ERR_NON_FINITE);
        }
        let q = project(&p, &[c0, c1, c2, c3]).ok_or(GRANBED_ERR_DEGENERATE)?;
        *out = GranbedQuadProjection {
            xi: q.xi,
            eta: q.eta,
            point: q.point,
            normal: q.normal,
            gap: q.gap,
            weights: q.weights,
            inside: i32::from(q.inside(GRANBED_INSIDE_TOLERANCE)),
        };
        Ok(GRANBED_OK)
    })())
}

/// One node-to-face constraint: the slave node and the master face's four
/// corners at the start of the step and predicted at its end (without
/// contact), their masses, and the projection of the predicted node on the
/// predicted face (from `granbed_project_node_on_quad`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedNodeFace {
    /// Slave node mass, kg (> 0). For several constraints on one node in
    /// a step, the mass sharing of physics.md §5.3 divides each node's mass
    /// (slave and master corners alike) by the number of constraints it
    /// takes part in.
    pub slave_mass: f64,
    /// Slave node position at the start of the step, m.
    pub slave_x_n: [f64; 3],
    /// Slave node predicted position, m.
    pub slave_x_pred: [f64; 3],
    /// Master corner masses, kg (> 0, also where the corner's weight is 0;
    /// shared as `slave_mass` is). A rigid master surface (a wall) is not
    /// given an infinite mass, which is refused: a mass many orders above
    /// the slave's, such as 1e20 kg, gives its limit, the force that moves
    /// only the slave.
    pub master_mass: [f64; 4],
    /// Master corners at the start of the step, `[corner][xyz]`, m.
    pub master_x_n: [[f64; 3]; 4],
    /// Master corners predicted, `[corner][xyz]`, m.
    pub master_x_pred: [[f64; 3]; 4],
    /// Bilinear weights of the corners at the contact point (each in
    /// [0, 1] and Σ = 1, within `GRANBED_UNIT_TOLERANCE`).
    pub weights: [f64; 4],
    /// The master face's outward unit normal at the contact point
    /// (| |n| − 1 | ≤ `GRANBED_UNIT_TOLERANCE`).
    pub normal: [f64; 3],
    /// Predicted signed gap, m (< 0: penetration, which the force closes;
    /// ≥ 0: no contact, zero force).
    pub gap: f64,
}

/// The kinematic force of one constraint.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedNodeFaceForce {
    /// Force on the slave node, N (normal + friction).
    pub slave: [f64; 3],
    /// Force on each master corner, −Nᵢ × the slave force, `[corner][xyz]`, N.
    pub master: [[f64; 3]; 4],
    /// The friction part of the slave force, N.
    pub friction: [f64; 3],
    /// Normal force magnitude, N.
    pub normal: f64,
    /// 1 if the friction force sits on the Coulomb cap (slip), else 0.
    pub slipping: i32,
}

/// Tolerance of the unit checks of `granbed_node_face_force`: the normal
/// must satisfy | |n| − 1 | ≤ this, the weights |Σ Nᵢ − 1| ≤ this.
pub const GRANBED_UNIT_TOLERANCE: f64 = 1e-6;
const _: () = assert!(GRANBED_UNIT_TOLERANCE == granbed_kernel::contact::pair::UNIT_TOLERANCE);

/// The force that closes the predicted gap of constraint `c` in one step,
/// shared by effective mass, with Coulomb friction from the relative
/// tangential motion of the step — the force granbed's contact applies to
/// each constraint (physics.md §5.3–§5.4). Apply it as an extra external
/// force at the step's corrector: x_{n+1} = x̃ + Δt² f/m.
///
/// * `weight`: partition weight w, 0 < w ≤ 1 (½ when both bodies' passes
///   hold the spot in a symmetric two-pass scheme, else 1).
/// * `friction`: Coulomb coefficient μ ≥ 0, finite (0: frictionless).
/// * `dt_squared`: Δt_{n+½} Δt_n > 0, finite, s².
///
/// A constraint with `gap` ≥ 0 is not in contact: the call succeeds and
/// writes a zero force (never a pull).
///
/// Returns `GRANBED_OK`; `GRANBED_ERR_NON_FINITE` (a position, a weight, a
/// normal component or the gap is NaN or infinite, or the force would
/// overflow: |gap| m_eff / Δt² beyond the range of a double); or
/// `GRANBED_ERR_INVALID_ARGUMENT`: a mass not finite or ≤ 0 (every master
/// corner's, whatever its weight), w, μ or Δt² outside its range, a
/// normal whose length differs from 1 by more than
/// `GRANBED_UNIT_TOLERANCE` (a zero normal included), or weights whose sum
/// differs from 1, or one of which lies outside [0, 1], by more than
/// `GRANBED_UNIT_TOLERANCE` (a point off the face). On an error `out`
/// is not written.
///
/// # Safety
/// `c` points to a `GranbedNodeFace`, `out` to a writable
/// `GranbedNodeFaceForce` (or NULL: an error).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn granbed_node_face_force(
    c: *const GranbedNodeFace,
    weight: f64,
    friction: f64,
    dt_squared: f64,
    out: *mut GranbedNodeFaceForce,
) -> i32 {
    status((|| {
        // SAFETY (both): the caller's contract.
        let c = unsafe { one(c) }?;
        let out = unsafe { one_mut(out) }?;
        let finite = c
            .slave_x_n
            .iter()
            .chain(&c.slave_x_pred)
            .chain(c.master_x_n.iter().flatten())
            .chain(c.master_x_pred.iter().flatten())
            .chain(&c.weights)
            .chain(&c.normal)
            .chain(core::iter::once(&c.gap))
            .all(|v| v.is_finite());
        if !finite {
            return Err(GRANBED_ERR_NON_FINITE);
        }
        let node = NodeFace {
            slave_mass: c.slave_mass,
            slave_x_n: c.slave_x_n,
            slave_x_pred: c.slave_x_pred,
            master_mass: c.master_mass,
            master_x_n: c.master_x_n,
            master_x_pred: c.master_x_pred,
            weights: c.weights,
            normal: c.normal,
            gap: c.gap,
        };
        // The kernel checks the masses, w, μ, Δt², the weights (their sum,
        // each in [0, 1]) and the normal's length (the positions are finite
        // here); it names the gap only when the force overflows.
        let r = node_face_force(&node, weight, friction, dt_squared).map_err(|e| match e {
            ContactError::InvalidParameter { field: "gap", .. } => GRANBED_ERR_NON_FINITE,
            _ => GRANBED_ERR_INVALID_ARGUMENT,
        })?;
        *out = GranbedNodeFaceForce {
            slave: r.force,
            master: c.weights.map(|w| r.force.map(|v| -w * v)),
            friction: r.friction,
            normal: r.normal,
            slipping: i32::from(r.slipping),
        };
        Ok(GRANBED_OK)
    })())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node 1 µm behind the face z = 0, all weight on corner 0.
    fn constraint() -> GranbedNodeFace {
        GranbedNodeFace {
            slave_mass: 1e-9,
            slave_x_pred: [0.0, 0.0, -1e-6],
            master_mass: [1e-9; 4],
            weights: [1.0, 0.0, 0.0, 0.0],
            normal: [0.0, 0.0, 1.0],
            gap: -1e-6,
            ..Default::default()
        }
    }

    fn call(c: &GranbedNodeFace, friction: f64, dt_squared: f64) -> (i32, GranbedNodeFaceForce) {
        let mut out = GranbedNodeFaceForce::default();
        // SAFETY: valid references.
        let code = unsafe { granbed_node_face_force(c, 1.0, friction, dt_squared, &mut out) };
        (code, out)
    }

    #[test]
    fn a_non_negative_gap_gives_a_zero_force() {
        let (code, f) = call(&constraint(), 0.3, 1e-16);
        assert_eq!(code, GRANBED_OK);
        assert!(f.normal > 0.0);
        for gap in [0.0, 1e-3] {
            let (code, f) = call(
                &GranbedNodeFace {
                    gap,
                    ..constraint()
                },
                0.3,
                1e-16,
            );
            assert_eq!(code, GRANBED_OK);
            assert_eq!((f.normal, f.slave, f.friction), (0.0, [0.0; 3], [0.0; 3]));
        }
    }

    #[test]
    fn bad_normals_masses_and_steps_are_invalid_arguments() {
        let c = constraint();
        for normal in [[0.0; 3], [0.0, 0.0, 1e6], [0.0, 0.0, 1.0 + 2e-6]] {
            let (code, _) = call(&GranbedNodeFace { normal, ..c }, 0.3, 1e-16);
            assert_eq!(code, GRANBED_ERR_INVALID_ARGUMENT, "{normal:?}");
        }
        let zero = GranbedNodeFace {
            master_mass: [1e-9, 0.0, 1e-9, 1e-9],
            ..c
        };
        assert_eq!(call(&zero, 0.3, 1e-16).0, GRANBED_ERR_INVALID_ARGUMENT);
        assert_eq!(call(&c, f64::NAN, 1e-16).0, GRANBED_ERR_INVALID_ARGUMENT);
        assert_eq!(call(&c, 0.3, 0.0).0, GRANBED_ERR_INVALID_ARGUMENT);
        assert_eq!(call(&c, 0.3, f64::INFINITY).0, GRANBED_ERR_INVALID_ARGUMENT);
    }
}
