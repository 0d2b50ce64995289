//! Kinematic (defence-node style) contact of granule nodes with a rigid
//! wall (a plane or the die cylinder), with Coulomb friction (physics.md
//! §5.4–§5.5).
//!
//! On the predicted configuration x̃, a node with gap g < 0 gets
//! the normal force F_n = m(−g)/Δt² along the inward normal n, which closes
//! the gap in one step. The stick trial F_t* = −m Δu_t/Δt² cancels the
//! tangential slip Δu_t of the step; if |F_t*| > μF_n the node slips with
//! F_t = μF_n F_t*/|F_t*|. Under selective mass scaling the body's rigid
//! displacement from the sweep's pre-solve ([`crate::contact::rigid`])
//! is added to the node's motion first: it closes part of the gap.
//!
//! Only a finite negative gap is a contact ([`penetrates`]): a node whose
//! predicted position is NaN or infinite (gap NaN or −∞) gets no force and
//! is not counted in [`WallForce::contacts`] — a force from it would be
//! NaN or infinite (a −∞ gap shows in [`WallForce::min_gap`]); the
//! driver's check of the motion (a non-finite kinetic energy) reports the
//! non-finite state. The passes check what they are given before any node
//! is touched ([`Wall::check`], the node range against every buffer,
//! μ and Δt²) and return [`ContactError`] rather than panic or write NaN.

use core::ops::Range;

use crate::Real;
use crate::contact::face_lists::check_len;
use crate::contact::pair::{ContactError, UNIT_TOLERANCE, check_friction, check_param, check_step};
use crate::contact::rigid::{RigidContact, RigidShift};

/// A rigid plane {x : n·x = d} whose inward unit normal n points into the
/// granule's side; it moves only along n, so it has no tangential motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Inward unit normal.
    pub normal: [Real; 3],
    /// Offset d, m: the gap of point x is n·x − d.
    pub offset: Real,
}

/// What a wall pass did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallForce {
    /// Σ F_n, N (magnitude of the normal force on the granule).
    pub normal: Real,
    /// Σ of the tangential (friction) forces, N.
    pub tangential: [Real; 3],
    /// Nodes in contact.
    pub contacts: usize,
    /// Most negative predicted gap, m (0 if none).
    pub min_gap: Real,
    /// Σ x ⊗ f over the forces f (normal and friction) the pass put on the
    /// nodes, x each node's predicted position, N·m (`virial[i][j]` =
    /// Σ x_i f_j): the wall's share of ∫ σ dV over a body at rest, by the
    /// virial theorem (∫ σ dV = Σ x ⊗ f over the forces on its boundary,
    /// without body forces).
    pub virial: [[Real; 3]; 3],
}

/// The nodes of one body as a contact pass sees them; one entry per node.
#[derive(Clone, Copy, Debug)]
pub struct PredictedNodes<'a> {
    /// Nodal masses used for the kinematic force, kg.
    pub mass: &'a [Real],
    /// Positions at t_n, m.
    pub x_n: &'a [[Real; 3]],
    /// Predicted positions at t_{n+1} (x_n + Δt v*), m.
    pub x_pred: &'a [[Real; 3]],
    /// The body's rigid displacement from the sweep's pre-solve under
    /// selective mass scaling ([`crate::contact::rigid`]); else
    /// [`RigidShift::NONE`]. With a shift, `mass` must be the stored masses
    /// m' (the pre-solve carries the rigid response), not
    /// `granule::damping::selective_contact_masses`, and the shift must be
    /// the one solved from [`add_wall_contacts`] on these nodes. Only nodes
    /// that penetrate on x̃ get a force: one that the shift would push into
    /// the wall is left to the next sweep.
    pub rigid_shift: RigidShift,
}

/// A rigid wall the granule surface nodes touch (physics.md §5.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Wall {
    /// A plane (a punch, a platen, a box side); it moves only along its
    /// normal, so it has no tangential motion.
    Plane(Plane),
    /// The inside of the die, a cylinder of `radius` (m) about the z axis:
    /// gap g = R − √(x² + y²), inward normal −(x, y, 0)/r.
    Die {
        /// Die radius R_d, m.
        radius: Real,
    },
}

impl Wall {
    /// False if no point within `radius` of `centre` can be behind the wall
    /// (the wall candidates of physics.md §5.1 from a bounding sphere): the
    /// gap of such a point is at least gap(centre) − radius, for the plane
    /// and for the die alike.
    pub fn may_touch(&self, centre: &[Real; 3], radius: Real) -> bool {
        self.gap(centre).0 - radius < 0.0
    }

    /// Checks the wall: a plane's normal of unit length (to
    /// [`UNIT_TOLERANCE`]) and a finite offset, the die's radius finite and
    /// > 0 ([`ContactError::InvalidParameter`]).
    pub fn check(&self) -> Result<(), ContactError> {
        match self {
            Wall::Plane(p) => {
                let n = p.normal;
                let len = crate::math::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                check_param(
                    (len - 1.0).abs() <= UNIT_TOLERANCE,
                    "plane normal length",
                    len,
                    "1 (a unit normal, to 1e-6)",
                )?;
                check_param(p.offset.is_finite(), "plane offset", p.offset, "finite")
            }
            Wall::Die { radius } => check_param(
                radius.is_finite() && *radius > 0.0,
                "die radius",
                *radius,
                "finite, > 0",
            ),
        }
    }

    /// Gap (m) and inward unit normal at point `x`.
    pub fn gap(&self, x: &[Real; 3]) -> (Real, [Real; 3]) {
        match self {
            Wall::Plane(p) => {
                let n = p.normal;
                (n[0] * x[0] + n[1] * x[1] + n[2] * x[2] - p.offset, n)
            }
            Wall::Die { radius } => {
                let r = crate::math::sqrt(x[0] * x[0] + x[1] * x[1]);
                if r > 0.0 {
                    (radius - r, [-x[0] / r, -x[1] / r, 0.0])
                } else {
                    (*radius, [1.0, 0.0, 0.0])
                }
            }
        }
    }
}

/// [`ContactError::BufferLength`] for the first of `buffers` (name,
/// length) shorter than the end of `nodes`; an empty range needs nothing.
fn check_nodes(
    nodes: &Range<usize>,
    buffers: &[(&'static str, usize)],
) -> Result<(), ContactError> {
    if nodes.is_empty() {
        return Ok(());
    }
    buffers
        .iter()
        .try_for_each(|&(buffer, len)| check_len(buffer, len, nodes.end))
}

/// The buffers of `body` and a non-empty `share` against `nodes`.
fn check_body(
    nodes: &Range<usize>,
    body: &PredictedNodes<'_>,
    share: &[u16],
) -> Result<(), ContactError> {
    check_nodes(
        nodes,
        &[
            ("mass", body.mass.len()),
            ("x_n", body.x_n.len()),
            ("x_pred", body.x_pred.len()),
        ],
    )?;
    if share.is_empty() {
        Ok(())
    } else {
        check_nodes(nodes, &[("share", share.len())])
    }
}

/// True if `gap` (m) is a penetration: finite and < 0. NaN (a NaN
/// position) and −∞ (an infinite one) are not.
#[inline]
pub fn penetrates(gap: Real) -> bool {
    gap < 0.0 && gap > Real::NEG_INFINITY
}

/// Adds the contact forces of `plane` on the nodes `nodes` (a range of node
/// indices, usually the surface nodes) into `f_c` (N), without mass
/// sharing; see [`wall_contact`] (and its errors).
pub fn plane_contact(
    plane: &Plane,
    friction: Real,
    dt_squared: Real,
    nodes: Range<usize>,
    body: &PredictedNodes<'_>,
    f_c: &mut [[Real; 3]],
) -> Result<WallForce, ContactError> {
    wall_contact(
        &Wall::Plane(*plane),
        friction,
        dt_squared,
        nodes,
        body,
        &[],
        f_c,
    )
}

/// Counts (in `count`, one per node) the nodes of `nodes` that penetrate
/// `wall` on the predicted configuration: each wall is one contact for the
/// mass sharing of §5.3. A NaN gap does not count; a node at infinity
/// (gap −∞, no force in [`wall_contact`]) does, which only shares a mass
/// nothing uses (one comparison per node, as in the force pass).
///
/// Errors: a bad wall ([`Wall::check`]); `x_pred` or `count` shorter than
/// the end of `nodes` ([`ContactError::BufferLength`]).
pub fn count_wall_contacts(
    wall: &Wall,
    nodes: Range<usize>,
    x_pred: &[[Real; 3]],
    count: &mut [u16],
) -> Result<(), ContactError> {
    wall.check()?;
    check_nodes(&nodes, &[("x_pred", x_pred.len()), ("count", count.len())])?;
    for i in nodes {
        if wall.gap(&x_pred[i]).0 < 0.0 {
            count[i] = count[i].saturating_add(1);
        }
    }
    Ok(())
}

/// Adds the contact forces of `wall` on the nodes `nodes` (a range of node
/// indices, usually the surface nodes) into `f_c` (N). `friction` is the
/// Coulomb μ (0 skips the friction work). `dt_squared` is Δt_{n+½}·Δt_n, the
/// product that maps a force to the position change of this step
/// (Δx = Δt_{n+½} Δt_n F/m), so the gap closes exactly even when Δt changes.
/// `share` holds each node's contact count n for the shared mass m/n
/// (empty: no sharing, the gap closes fully in one step).
///
/// Errors, before any force is added: a bad wall ([`Wall::check`]), μ not
/// finite and ≥ 0 or Δt² not finite and > 0
/// ([`ContactError::InvalidParameter`]); a buffer of `body`, a non-empty
/// `share` or `f_c` shorter than the end of `nodes`
/// ([`ContactError::BufferLength`]).
pub fn wall_contact(
    wall: &Wall,
    friction: Real,
    dt_squared: Real,
    nodes: Range<usize>,
    body: &PredictedNodes<'_>,
    share: &[u16],
    f_c: &mut [[Real; 3]],
) -> Result<WallForce, ContactError> {
    wall.check()?;
    check_step(friction, dt_squared)?;
    check_body(&nodes, body, share)?;
    check_nodes(&nodes, &[("f_c", f_c.len())])?;
    let (mass, x_n, x_pred) = (body.mass, body.x_n, body.x_pred);
    let inv_dt2 = 1.0 / dt_squared;
    let mut out = WallForce::default();
    let shifted = body.rigid_shift != RigidShift::NONE;
    for i in nodes {
        let xp = x_pred[i];
        let (gap, n) = wall.gap(&xp);
        // [`penetrates`] in two steps, so that the common case (no
        // contact) costs one comparison as before; NaN fails it.
        let below = gap < 0.0;
        if !below {
            continue;
        }
        // `min_gap` is the unshifted depth, also of a node that the shift
        // clears (which gets no force and does not count in `contacts`),
        // and of a node at infinity (−∞, which gets no force either).
        out.min_gap = crate::math::min(out.min_gap, gap);
        if gap == Real::NEG_INFINITY {
            continue;
        }
        let mut du = [xp[0] - x_n[i][0], xp[1] - x_n[i][1], xp[2] - x_n[i][2]];
        let mut gap = gap;
        if shifted {
            // The rigid pre-solve's displacement closes part of the gap
            // and is part of the node's motion over the step.
            let u = body.rigid_shift.at(&x_n[i]);
            gap += u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
            if !penetrates(gap) {
                continue;
            }
            for a in 0..3 {
                du[a] += u[a];
            }
        }
        let m = shared_wall_mass(mass, share, i);
        let fn_mag = m * (-gap) * inv_dt2;
        let mut f = [fn_mag * n[0], fn_mag * n[1], fn_mag * n[2]];
        if friction > 0.0 {
            let dn = du[0] * n[0] + du[1] * n[1] + du[2] * n[2];
            let mut ft = [0.0; 3];
            for a in 0..3 {
                ft[a] = -m * (du[a] - dn * n[a]) * inv_dt2;
            }
            let ft_mag = crate::math::sqrt(ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]);
            let cap = friction * fn_mag;
            if ft_mag > cap {
                let s = cap / ft_mag;
                ft = ft.map(|c| c * s);
            }
            for a in 0..3 {
                f[a] += ft[a];
                out.tangential[a] += ft[a];
            }
        }
        for a in 0..3 {
            f_c[i][a] += f[a];
        }
        for (row, x) in out.virial.iter_mut().zip(xp) {
            for (v, f) in row.iter_mut().zip(f) {
                *v += x * f;
            }
        }
        out.normal += fn_mag;
        out.contacts += 1;
    }
    Ok(out)
}

/// Node `i`'s mass shared among its `share` contacts, m/max(1, n), kg.
fn shared_wall_mass(mass: &[Real], share: &[u16], i: usize) -> Real {
    mass[i] / Real::from(share.get(i).copied().unwrap_or(1).max(1))
}

/// Adds the nodes of `nodes` that penetrate `wall` on the predicted
/// configuration to the body's rigid pre-solve (`contact::rigid`,
/// selective mass scaling): at x_n, with the stiffness (shared mass, `share`
/// as in [`wall_contact`]) and the closure its force will have — along the
/// wall's normal at x̃ (−gap), and with friction (μ = `friction` > 0) as a
/// sticking point that also cancels the tangential slip of the step.
///
/// Errors, before any contact is added: a bad wall ([`Wall::check`]) or μ
/// not finite and ≥ 0 ([`ContactError::InvalidParameter`]); a buffer of
/// `body` or a non-empty `share` shorter than the end of `nodes`
/// ([`ContactError::BufferLength`]).
pub fn add_wall_contacts(
    wall: &Wall,
    friction: Real,
    nodes: Range<usize>,
    body: &PredictedNodes<'_>,
    share: &[u16],
    system: &mut RigidContact,
) -> Result<(), ContactError> {
    wall.check()?;
    check_friction(friction)?;
    check_body(&nodes, body, share)?;
    for i in nodes {
        let (xp, x) = (body.x_pred[i], body.x_n[i]);
        let (gap, n) = wall.gap(&xp);
        if !penetrates(gap) {
            continue;
        }
        let m = shared_wall_mass(body.mass, share, i);
        if friction > 0.0 {
            let du = [xp[0] - x[0], xp[1] - x[1], xp[2] - x[2]];
            let dn = du[0] * n[0] + du[1] * n[1] + du[2] * n[2];
            let target: [Real; 3] = core::array::from_fn(|a| -gap * n[a] - (du[a] - dn * n[a]));
            system.add_stick(&x, m, &target);
        } else {
            system.add(&x, &n, m, -gap);
        }
    }
    Ok(())
}
