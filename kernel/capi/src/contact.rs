//! Node-to-quad projection and the kinematic contact force of one
//! node-to-face constraint (physics.md §5.2–§5.4).

use granbed_kernel::contact::pair::{NodeFace, node_face_force};
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
    /// Local coordinate ξ* of the closest point (the face is [−1, 1]²).
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
    /// 1 if |ξ*|, |η*| ≤ 1 + [`GRANBED_INSIDE_TOLERANCE`], else 0.
    pub inside: i32,
}

/// Projects the point `p` (3 doubles, m) on the bilinear quad `quad`
/// (4 corners × xyz = 12 doubles, counter-clockwise seen from outside, so
/// the normal points out) by Newton's method on the closest-point problem.
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_NON_FINITE`, or
/// `GRANBED_ERR_DEGENERATE` (zero-length edge vectors or zero normal).
///
/// # Safety
/// `p` points to 3 doubles, `quad` to 12, `out` to a writable
/// [`GranbedQuadProjection`] (or they are NULL: an error).
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
/// predicted face (from [`granbed_project_node_on_quad`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GranbedNodeFace {
    /// Slave node mass, kg (> 0; divide by the node's contact count for
    /// the mass sharing of physics.md §5.3).
    pub slave_mass: f64,
    /// Slave node position at the start of the step, m.
    pub slave_x_n: [f64; 3],
    /// Slave node predicted position, m.
    pub slave_x_pred: [f64; 3],
    /// Master corner masses, kg (> 0).
    pub master_mass: [f64; 4],
    /// Master corners at the start of the step, `[corner][xyz]`, m.
    pub master_x_n: [[f64; 3]; 4],
    /// Master corners predicted, `[corner][xyz]`, m.
    pub master_x_pred: [[f64; 3]; 4],
    /// Bilinear weights of the corners at the contact point (Σ = 1).
    pub weights: [f64; 4],
    /// The master face's outward unit normal at the contact point.
    pub normal: [f64; 3],
    /// Predicted signed gap, m (< 0: penetration, which the force closes).
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

/// The force that closes the predicted gap of constraint `c` in one step,
/// shared by effective mass, with Coulomb friction from the relative
/// tangential motion of the step — the force granbed's contact applies to
/// each constraint (physics.md §5.3–§5.4). Apply it as an extra external
/// force at the step's corrector: x_{n+1} = x̃ + Δt² f/m.
///
/// * `weight`: partition weight w, 0 < w ≤ 1 (½ when both bodies' passes
///   hold the spot in a symmetric two-pass scheme, else 1).
/// * `friction`: Coulomb coefficient μ ≥ 0 (0: frictionless).
/// * `dt_squared`: Δt_{n+½} Δt_n > 0, s².
///
/// Returns `GRANBED_OK`, `GRANBED_ERR_INVALID_ARGUMENT` (a mass ≤ 0, w, μ
/// or Δt² outside its range) or `GRANBED_ERR_NON_FINITE`.
///
/// # Safety
/// `c` points to a [`GranbedNodeFace`], `out` to a writable
/// [`GranbedNodeFaceForce`] (or NULL: an error).
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
        let masses_ok = core::iter::once(c.slave_mass)
            .chain(c.master_mass)
            .all(|m| m.is_finite() && m > 0.0);
        let scalars_ok = weight > 0.0
            && weight <= 1.0
            && friction.is_finite()
            && friction >= 0.0
            && dt_squared.is_finite()
            && dt_squared > 0.0;
        if !masses_ok || !scalars_ok {
            return Err(GRANBED_ERR_INVALID_ARGUMENT);
        }
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
        let r = node_face_force(&node, weight, friction, dt_squared);
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
