//! The explicit central-difference step of one granule, split around the
//! contact pass (physics.md §4.1, Pronto-style predictor/corrector):
//!
//! * [`predict`]: element forces f_int(x_n), selective damping forces f_d
//!   from v_{n−½}, v* = v_{n−½} + Δt_n M⁻¹(f_g − f_int + f_d), predictor
//!   x̃ = x_n + Δt v*, and f_c cleared for the contact pass;
//! * the caller adds contact forces f_c computed on x̃;
//! * [`correct`]: v_{n+½} = v* + Δt_n M⁻¹ f_c, x_{n+1} = x_n + Δt v_{n+½},
//!   and the work of every force over the step.
//!
//! Δt_n = (Δt_{n−½} + Δt_{n+½})/2. Components flagged in `fixed` (symmetry
//! planes) keep zero velocity.
//!
//! **Selective mass scaling** ([`Loads::selective_mass_factor`] F > 1, an
//! addition to physics.md §4 for quasi-static runs): the stored masses m'
//! are F × the physical ones, and the mass matrix is
//! M' = M'(1 − P) + (M'/F) P, with P the mass-orthogonal projection onto
//! the six rigid modes (`damping::rigid_motion`): the deformational modes
//! carry F× their inertia (so ω_max, and with it the stable step, is that
//! of uniform scaling by F), the translation and spin of the granule their
//! physical inertia. Its inverse is exact and cheap,
//! M'⁻¹f = f/m' + (F − 1) P(f/m'), so every velocity update here adds
//! (F − 1)× the rigid part of its increment, and the kinetic energy is
//! ½ v·M'v = ½ Σ m'|v|² − ½ (1 − 1/F) Σ m'|Pv|². Forces with no net force
//! or moment (element, damping) get no rigid part; gravity (a uniform
//! field) is all rigid part, so the caller passes g/F, as with uniform
//! scaling, and the granule falls at g.

use crate::Real;
use crate::granule::damping::{
    MomentSums, RigidFrame, RigidMotion, damping_forces_in, damping_forces_of, selective_excess_of,
};
use crate::granule::forces::{ElementSettings, ForceSummary, ForcesError, internal_forces};
use crate::material::Material;
use crate::mesh::reference::ReferenceMesh;
use crate::tensor::{VOIGT_IDENTITY, Voigt};

/// Caller-owned state of one granule. Node buffers have one entry per node
/// of its mesh; `cp_inv` has hexes × points per element entries.
pub struct GranuleBuffers<'a> {
    /// Positions x_n, m.
    pub x: &'a mut [[Real; 3]],
    /// Velocities v_{n−½}, m/s.
    pub v: &'a mut [[Real; 3]],
    /// Scratch: velocity update before contact v*, m/s.
    pub v_star: &'a mut [[Real; 3]],
    /// Scratch: predicted positions x̃, m.
    pub x_pred: &'a mut [[Real; 3]],
    /// Internal + hourglass forces at x_n, N.
    pub f_int: &'a mut [[Real; 3]],
    /// Contact forces of the step, N (filled by the caller's contact pass).
    pub f_c: &'a mut [[Real; 3]],
    /// Damping forces of the step, N.
    pub f_d: &'a mut [[Real; 3]],
    /// Lumped nodal masses, kg.
    pub mass: &'a mut [Real],
    /// Per node, bit a set if velocity component a is held at 0.
    pub fixed: &'a mut [u8],
    /// Per integration point, C_p⁻¹ (Voigt), element by element (F-bar's
    /// eight in [`crate::element::hex8::gauss_points`] order).
    pub cp_inv: &'a mut [Voigt],
}

impl GranuleBuffers<'_> {
    /// The first buffer whose length is wrong: (name, expected, got).
    pub fn wrong_length(
        &self,
        nodes: usize,
        states: usize,
    ) -> Option<(&'static str, usize, usize)> {
        [
            ("x", self.x.len()),
            ("v", self.v.len()),
            ("v_star", self.v_star.len()),
            ("x_pred", self.x_pred.len()),
            ("f_int", self.f_int.len()),
            ("f_c", self.f_c.len()),
            ("f_d", self.f_d.len()),
            ("mass", self.mass.len()),
            ("fixed", self.fixed.len()),
        ]
        .into_iter()
        .map(|(name, got)| (name, nodes, got))
        .chain(core::iter::once(("cp_inv", states, self.cp_inv.len())))
        .find(|(_, expected, got)| expected != got)
    }

    /// The virgin state on `mesh`: x = X, v = 0, C_p⁻¹ = 1, masses ρ0 × the
    /// lumped volumes, nothing fixed. Lengths must be right (one entry per
    /// mesh node; [`Self::wrong_length`] names a mismatch, and the step
    /// functions refuse one): a buffer shorter or longer than the mesh is
    /// filled as far as both go, without a panic.
    pub fn reset(&mut self, mesh: &ReferenceMesh<'_>, mat: &Material) {
        for (x, p) in self.x.iter_mut().zip(mesh.mesh.positions) {
            *x = *p;
        }
        self.v.fill([0.0; 3]);
        self.cp_inv.fill(VOIGT_IDENTITY);
        self.fixed.fill(0);
        for (m, vol) in self.mass.iter_mut().zip(mesh.node_volume) {
            *m = mat.density0 * vol;
        }
    }
}

/// Time-step sizes around step n, s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSizes {
    /// Δt_{n−½}, the previous step.
    pub dt_prev: Real,
    /// Δt_{n+½}, this step.
    pub dt: Real,
}

impl StepSizes {
    /// Δt_n = (Δt_{n−½} + Δt_{n+½})/2, the velocity-update step.
    pub fn dt_n(&self) -> Real {
        0.5 * (self.dt_prev + self.dt)
    }

    /// Δt_{n+½}·Δt_n, which maps a contact force to this step's position
    /// change (for the kinematic contact passes).
    pub fn contact_dt_squared(&self) -> Real {
        self.dt * self.dt_n()
    }
}

/// Body loads and damping of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loads {
    /// Gravity acting in −z, m/s².
    pub gravity_m_s2: Real,
    /// Damping coefficient c, 1/s.
    pub damping_c: Real,
    /// Whether the granule has free rigid modes (false with symmetry planes).
    pub rigid_modes: bool,
    /// Selective mass scaling F ≥ 1 (module docs): the stored masses are F ×
    /// the physical ones and act on the deformational modes only; the rigid
    /// modes keep the physical inertia. 1: the stored masses act on every
    /// mode (no scaling, or uniform scaling by the caller). Ignored without
    /// free rigid modes; a factor that is not finite or not above 1 means
    /// none.
    pub selective_mass_factor: Real,
}

impl Loads {
    /// The factor (F − 1) by which a velocity increment's rigid part is
    /// added again, or `None` when the masses act on every mode.
    fn rigid_boost(&self) -> Option<Real> {
        let f = self.selective_mass_factor;
        (self.rigid_modes && f > 1.0 && f.is_finite()).then_some(f - 1.0)
    }
}

/// Work of each force over one step (midpoint rule on
/// ½(Δx_{n−½} + Δx_{n+½})), J, the kinetic energy at n+½, the largest
/// nodal speed and, under selective mass scaling, the rigid frame at
/// x_{n+1}.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepWork {
    /// Work of the internal + hourglass forces (energy taken up by the body).
    pub internal: Real,
    /// Work of the contact forces on the nodes.
    pub contact: Real,
    /// Energy removed by damping.
    pub damping: Real,
    /// Work of gravity.
    pub gravity: Real,
    /// Kinetic energy ½ Σ m v_{n+½}².
    pub kinetic: Real,
    /// Largest nodal |v_{n+½}|², m²/s² (for a driver's runaway watchdog).
    pub max_speed_squared: Real,
    /// The granule's rigid frame at x_{n+1} when the corrector took it
    /// (under selective mass scaling, for the kinetic energy): the bits of
    /// [`RigidFrame::of`] on the new positions, so a driver may hand it to
    /// the next step's [`predict_in`] and [`correct_in`] instead of taking
    /// it again, while the positions and masses stay as they are.
    pub next_frame: Option<RigidFrame>,
    /// With `next_frame`, the rigid part of the new velocities v_{n+½} in
    /// it: the bits of `next_frame.motion(mass, x, |i| v[i])` on the new
    /// positions, which is the projection the next step's damping takes
    /// ([`predict_in`]'s `velocity_motion`).
    pub next_motion: Option<RigidMotion>,
}

/// Checks a step's inputs before it writes anything: every node buffer as
/// long as `x`, and Δt_{n+½} finite and > 0, Δt_{n−½} finite and ≥ 0 (the
/// node masses are the caller's, set by [`GranuleBuffers::reset`]; they
/// are not re-checked every step). `cp_inv` is checked against the mesh by
/// the element pass.
fn check_step(b: &GranuleBuffers<'_>, sizes: StepSizes) -> Result<(), ForcesError> {
    if let Some((buffer, expected, got)) = b.wrong_length(b.x.len(), b.cp_inv.len()) {
        return Err(ForcesError::BufferLength {
            buffer,
            expected,
            got,
        });
    }
    for (field, value, ok, allowed) in [
        ("dt", sizes.dt, sizes.dt > 0.0, "finite and > 0 s"),
        (
            "dt_prev",
            sizes.dt_prev,
            sizes.dt_prev >= 0.0,
            "finite and >= 0 s",
        ),
    ] {
        if !(ok && value.is_finite()) {
            return Err(ForcesError::InvalidParameter {
                field,
                value,
                allowed,
            });
        }
    }
    Ok(())
}

/// First half of a step: forces at x_n, damping, v*, x̃; clears `f_c`.
/// Errors: a buffer of the wrong length or a bad step size
/// ([`ForcesError`]), before anything is written; a failed element.
pub fn predict(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    b: &mut GranuleBuffers<'_>,
    sizes: StepSizes,
    loads: &Loads,
) -> Result<ForceSummary, ForcesError> {
    let frame = own_frame(b, loads.rigid_modes);
    predict_in(&frame, None, mesh, mat, settings, b, sizes, loads)
}

/// [`predict`] with the granule's [`RigidFrame`] at x_n taken by the
/// caller, who may hand the same frame to [`correct_in`] after the
/// contact pass (x_n does not change in between) and so take it once per
/// step instead of three times; the bits of [`predict`]. `frame` must be
/// `RigidFrame::of(b.mass, b.x)`; it is not read when `loads.rigid_modes`
/// is false. `velocity_motion`, if given, must be
/// `frame.motion(b.mass, b.x, |i| b.v[i])`, the rigid part of v_{n−½} that
/// the damping leaves undamped (the last corrector's
/// [`StepWork::next_motion`]); `None` takes it here.
#[allow(clippy::too_many_arguments)]
pub fn predict_in(
    frame: &RigidFrame,
    velocity_motion: Option<&RigidMotion>,
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    b: &mut GranuleBuffers<'_>,
    sizes: StepSizes,
    loads: &Loads,
) -> Result<ForceSummary, ForcesError> {
    check_step(b, sizes)?;
    let summary = internal_forces(mesh, mat, settings, b.x, b.cp_inv, b.f_int)?;
    let frame = loads.rigid_modes.then_some(frame);
    match (frame, velocity_motion) {
        (Some(_), Some(motion)) => {
            damping_forces_of(motion, b.mass, b.x, b.v, loads.damping_c, b.f_d)
        }
        _ => damping_forces_in(frame, b.mass, b.x, b.v, loads.damping_c, b.f_d),
    }
    advance_predictor(b, sizes, loads, Motion::Deforming(frame));
    Ok(summary)
}

/// The frame of `b` at x_n if the rigid modes are free, else a zero one
/// (not read then).
fn own_frame(b: &GranuleBuffers<'_>, rigid_modes: bool) -> RigidFrame {
    if rigid_modes {
        RigidFrame::of(b.mass, b.x)
    } else {
        RigidFrame::default()
    }
}

/// First half of a step for a granule that is undeformed (x_n a rigid
/// motion of the reference, C_p⁻¹ untouched) and translating (every node
/// has the same velocity): its internal force and its damping force, which
/// acts on the non-rigid part of the velocity only, are zero, so no element
/// is evaluated. Up to round-off — [`predict`] would see forces of order
/// ε·E·A from the rotated coordinates — this is [`predict`]'s step.
///
/// The caller vouches for the two conditions (a granule placed at rest or
/// translating, never touched since); the step keeps them true, because
/// with `f_c = 0` every node receives the same gravity acceleration. The
/// summary reports an undeformed body: J = 1, no plastic or hourglass work.
/// Errors as [`predict`]'s checks, before anything is written.
pub fn predict_rigid(
    b: &mut GranuleBuffers<'_>,
    sizes: StepSizes,
    loads: &Loads,
) -> Result<ForceSummary, ForcesError> {
    check_step(b, sizes)?;
    b.f_int.fill([0.0; 3]);
    b.f_d.fill([0.0; 3]);
    advance_predictor(b, sizes, loads, Motion::Translating);
    Ok(ForceSummary {
        min_j: 1.0,
        ..ForceSummary::default()
    })
}

/// Whether velocity component `a` of a node with `fixed` bits is held at
/// zero.
#[inline]
fn held(fixed: u8, a: usize) -> bool {
    fixed & (1 << a) != 0
}

/// How a granule moves in [`advance_predictor`].
#[derive(Clone, Copy)]
enum Motion<'f> {
    /// Every node has the same increment (a rigid granule under gravity),
    /// which is then its own rigid part.
    Translating,
    /// Anything else; the frame at x_n when the rigid modes are free.
    Deforming(Option<&'f RigidFrame>),
}

/// v* = v + Δt_n M⁻¹ (f_g − f_int + f_d) and x̃ = x + Δt v* (held components
/// stay at rest); clears `f_c`.
fn advance_predictor(
    b: &mut GranuleBuffers<'_>,
    sizes: StepSizes,
    loads: &Loads,
    motion: Motion<'_>,
) {
    let (dt, dt_n, g) = (sizes.dt, sizes.dt_n(), loads.gravity_m_s2);
    let boost = loads.rigid_boost();
    // Buffers cut to the node count, so the loops index without bounds
    // checks (callers check the lengths with `GranuleBuffers::wrong_length`).
    let n = b.x.len();
    let (mass, fixed, x, v) = (&b.mass[..n], &b.fixed[..n], &b.x[..n], &b.v[..n]);
    let (f_int, f_d) = (&b.f_int[..n], &b.f_d[..n]);
    let (v_star, x_pred) = (&mut b.v_star[..n], &mut b.x_pred[..n]);
    // The increments Δt_n (f_g − f_int + f_d)/m, one division per
    // component, kept in v* until v* is formed (the rigid projection reads
    // each twice).
    for i in 0..n {
        for a in 0..3 {
            let f_g = if a == 2 { -g * mass[i] } else { 0.0 };
            let force = f_g - f_int[i][a] + f_d[i][a];
            v_star[i][a] = if held(fixed[i], a) {
                0.0
            } else {
                dt_n * force / mass[i]
            };
        }
    }
    let (frame, translating) = match motion {
        Motion::Translating => (None, true),
        Motion::Deforming(frame) => (frame, false),
    };
    let rigid = match (boost, frame) {
        (Some(_), Some(frame)) => {
            let increments: &[[Real; 3]] = v_star;
            Some(frame.motion(mass, x, |i| increments[i]))
        }
        _ => None,
    };
    for i in 0..n {
        let extra = match (boost, &rigid) {
            (Some(k), Some(r)) => r.velocity_at(&x[i]).map(|r| k * r),
            _ => [0.0; 3],
        };
        for (a, extra) in extra.into_iter().enumerate() {
            let dv = v_star[i][a];
            v_star[i][a] = if held(fixed[i], a) {
                0.0
            } else {
                match boost {
                    None => v[i][a] + dv,
                    Some(k) if translating => v[i][a] + (dv + k * dv),
                    Some(_) => v[i][a] + (dv + extra),
                }
            };
            x_pred[i][a] = x[i][a] + dt * v_star[i][a];
        }
    }
    b.f_c.fill([0.0; 3]);
}

/// Whether a step Δt_n lets [`contact_increment`] skip the division of a
/// zero force: Δt_n > 0 and finite.
#[inline]
fn division_skippable(dt_n: Real) -> bool {
    dt_n > 0.0 && dt_n.is_finite()
}

/// The velocity increment Δt_n f/m of a contact force component `force`
/// on a node of mass `m`, with the bits of `dt_n * force / m`; a zero
/// force (most nodes: contact acts on the surface only) skips the
/// division, which gives the same signed zero when `dt_ok`
/// ([`division_skippable`]) and m > 0.
#[inline]
fn contact_increment(dt_ok: bool, dt_n: Real, force: Real, m: Real) -> Real {
    if force == 0.0 && dt_ok && m > 0.0 {
        force
    } else {
        dt_n * force / m
    }
}

/// Second half of a step: applies the contact forces in `f_c` (with the
/// selective mass matrix of `loads`, module docs), advances x and v, and
/// returns the work of every force (gravity `loads.gravity_m_s2`).
/// Errors as [`predict`]'s checks, before anything is written.
pub fn correct(
    b: &mut GranuleBuffers<'_>,
    sizes: StepSizes,
    loads: &Loads,
) -> Result<StepWork, ForcesError> {
    let frame = own_frame(b, loads.rigid_boost().is_some());
    correct_in(&frame, b, sizes, loads)
}

/// [`correct`] with the granule's [`RigidFrame`] at x_n (before this
/// step's update) taken by the caller, as for [`predict_in`]; the bits of
/// [`correct`]. `frame` is read only under selective mass scaling, where
/// the returned [`StepWork::next_frame`] is the frame at x_{n+1}.
pub fn correct_in(
    frame: &RigidFrame,
    b: &mut GranuleBuffers<'_>,
    sizes: StepSizes,
    loads: &Loads,
) -> Result<StepWork, ForcesError> {
    check_step(b, sizes)?;
    let (dt, dt_n) = (sizes.dt, sizes.dt_n());
    let dt_ok = division_skippable(dt_n);
    let gravity_m_s2 = loads.gravity_m_s2;
    let boost = loads.rigid_boost();
    // Every buffer cut to the node count up front, so the loops below
    // index without bounds checks (the same bits); `check_step` made sure
    // they are that long.
    let n = b.x.len();
    let (mass, fixed, f_c) = (&b.mass[..n], &b.fixed[..n], &b.f_c[..n]);
    let rigid = match boost {
        Some(_) => frame.motion(mass, &b.x[..n], |i| {
            core::array::from_fn(|a| {
                if held(fixed[i], a) {
                    0.0
                } else {
                    contact_increment(dt_ok, dt_n, f_c[i][a], mass[i])
                }
            })
        }),
        None => RigidMotion::REST,
    };
    let (v_star, f_int, f_d) = (&b.v_star[..n], &b.f_int[..n], &b.f_d[..n]);
    let (x, v) = (&mut b.x[..n], &mut b.v[..n]);
    let mut w = StepWork::default();
    // Under selective scaling, the sums of the frame at x_{n+1} and of the
    // rigid part of v_{n+½}, added as the loop makes them.
    let mut sums = MomentSums::default();
    for i in 0..n {
        let m = mass[i];
        let extra = match boost {
            Some(k) => rigid.velocity_at(&x[i]).map(|r| k * r),
            None => [0.0; 3],
        };
        for (a, extra) in extra.into_iter().enumerate() {
            let v_new = if held(fixed[i], a) {
                0.0
            } else if boost.is_some() {
                v_star[i][a] + (contact_increment(dt_ok, dt_n, f_c[i][a], m) + extra)
            } else {
                v_star[i][a] + contact_increment(dt_ok, dt_n, f_c[i][a], m)
            };
            let dx = 0.5 * (sizes.dt_prev * v[i][a] + dt * v_new);
            w.internal += f_int[i][a] * dx;
            w.contact += f_c[i][a] * dx;
            w.damping -= f_d[i][a] * dx;
            if a == 2 {
                w.gravity -= gravity_m_s2 * m * dx;
            }
            v[i][a] = v_new;
            x[i][a] += dt * v_new;
            w.kinetic += 0.5 * m * v_new * v_new;
        }
        if boost.is_some() {
            sums.add(m, &x[i], &v[i]);
        }
    }
    if let Some(k) = boost {
        // ½ v·M'v: the rigid part carries m'/F, not m' (module docs). The
        // frame and motion have the bits of RigidFrame::of and its motion.
        let (next, motion) = sums.frame_and_motion(mass, x, v);
        w.kinetic -= selective_excess_of(&motion, k + 1.0);
        w.next_frame = Some(next);
        w.next_motion = Some(motion);
    }
    // A pass of its own keeps the loop above as it was (folding this into
    // it doubled its cost); f64::max is maxsd, no libm call (a NaN speed
    // also makes the kinetic energy NaN, which the driver reports).
    w.max_speed_squared = b.v.iter().fold(0.0, |m: Real, v| {
        m.max(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    });
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::{contact_increment, division_skippable};
    use crate::Real;

    /// Skipping the division of a zero force gives `dt_n * f / m` to the
    /// bit, signed zeros included; where it could not (Δt_n or m zero,
    /// negative, infinite or NaN) the division is done.
    #[test]
    fn contact_increment_has_the_bits_of_the_division() {
        let values: [Real; 9] = [
            0.0,
            -0.0,
            1e-300,
            -3.5,
            2.0,
            Real::INFINITY,
            -Real::INFINITY,
            Real::NAN,
            5e-324,
        ];
        for dt_n in values {
            let dt_ok = division_skippable(dt_n);
            for force in values {
                for m in values {
                    let want = dt_n * force / m;
                    let got = contact_increment(dt_ok, dt_n, force, m);
                    assert!(
                        got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                        "dt {dt_n:e} f {force:e} m {m:e}: {got:e} vs {want:e}"
                    );
                }
            }
        }
    }
}
