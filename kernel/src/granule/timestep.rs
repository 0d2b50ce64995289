//! The stable time step of a granule (physics.md §4.2): the element estimate
//! Δt = C·min_e L_e/c_d (L_e = V_e/A_e,max from the current geometry,
//! c_d = √((λ+2μ)/ρ0)), and the global estimate 2/ω_max by power iteration.

use crate::Real;
use crate::element::hex8;
use crate::element::reference::hex_volume;
use crate::granule::forces::{ElementSettings, internal_forces};
use crate::material::Material;
use crate::mesh::reference::ReferenceMesh;
use crate::tensor::Voigt;

/// Smallest characteristic length min_e V_e/A_e,max at positions `x` (m);
/// `None` if an element is inverted or names a node beyond `x`.
pub fn min_element_length(mesh: &ReferenceMesh<'_>, x: &[[Real; 3]]) -> Option<Real> {
    let mut min = Real::INFINITY;
    for hex in mesh.mesh.hexes {
        let mut xe = [[0.0; 3]; 8];
        for (xi, &id) in xe.iter_mut().zip(hex) {
            *xi = *x.get(id as usize)?;
        }
        let volume = hex_volume(&xe)?;
        min = crate::math::min(min, volume / hex8::max_face_area(&xe));
    }
    Some(min)
}

/// Dilatational wave speed c_d = √((λ+2μ)/ρ0), m/s.
pub fn wave_speed(mat: &Material) -> Real {
    crate::math::sqrt(mat.p_wave_modulus() / mat.density0)
}

/// Element estimate of the stable step, s: `safety` × min L_e / c_d;
/// `None` if `safety` is not finite and > 0, or as [`min_element_length`].
pub fn element_time_step(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    x: &[[Real; 3]],
    safety: Real,
) -> Option<Real> {
    if !(safety > 0.0 && safety.is_finite()) {
        return None;
    }
    Some(safety * min_element_length(mesh, x)? / wave_speed(mat))
}

/// The largest safety factor [`TimeStepControl::estimate`] takes: twice
/// the stability limit, what a test that provokes an instability uses (the
/// bed scene's `time_step_safety` allows it for that).
pub const MAX_SAFETY: Real = 2.0;

/// Scratch buffers of [`max_frequency`]: node buffers have one entry per
/// node, `cp_scratch` as many entries as the granule's `cp_inv`.
pub struct PowerIterationBuffers<'a> {
    /// In: start vector (any non-zero field; the previous result converges
    /// fastest). Out: the dominant mode estimate, M-normalised.
    pub mode: &'a mut [[Real; 3]],
    /// Scratch: perturbed positions.
    pub x_pert: &'a mut [[Real; 3]],
    /// Scratch: forces at x + h·mode.
    pub f_plus: &'a mut [[Real; 3]],
    /// Scratch: forces at x − h·mode.
    pub f_minus: &'a mut [[Real; 3]],
    /// Scratch: a copy of the state, so the estimate leaves it untouched.
    pub cp_scratch: &'a mut [Voigt],
}

/// The configuration a granule is linearised about.
#[derive(Clone, Copy, Debug)]
pub struct Linearisation<'a> {
    /// Lumped nodal masses, kg.
    pub mass: &'a [Real],
    /// Node positions, m.
    pub x: &'a [[Real; 3]],
    /// Integration-point states C_p⁻¹ (left untouched).
    pub cp_inv: &'a [Voigt],
}

/// Largest angular frequency ω_max (rad/s) of the granule linearised at
/// `at`, by `iterations` power iterations on M⁻¹K with matrix-free products
/// K·u ≈ [f(x + hu) − f(x − hu)]/(2h). The stable central-difference step
/// is 2/ω_max. `None` if an element fails at a perturbed configuration,
/// or a buffer's length is not the granule's (`mass` and every node buffer
/// one entry per position, `cp_scratch` one per state).
pub fn max_frequency(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    at: &Linearisation<'_>,
    buf: &mut PowerIterationBuffers<'_>,
    iterations: u32,
) -> Option<Real> {
    let (mass, x, cp_inv) = (at.mass, at.x, at.cp_inv);
    let nodes = x.len();
    if [
        mass.len(),
        buf.mode.len(),
        buf.x_pert.len(),
        buf.f_plus.len(),
        buf.f_minus.len(),
    ]
    .into_iter()
    .any(|n| n != nodes)
        || buf.cp_scratch.len() != cp_inv.len()
    {
        return None;
    }
    let size = crate::math::max(min_element_length(mesh, x)?, Real::MIN_POSITIVE);
    let mut lambda = 0.0;
    for _ in 0..iterations {
        // Normalise the mode to unit M-norm, scaled so h·u is 1e-7 of an element.
        let norm2: Real = buf
            .mode
            .iter()
            .zip(mass)
            .map(|(u, m)| m * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]))
            .sum();
        if norm2.is_nan() || norm2 <= 0.0 {
            return None;
        }
        let inv = 1.0 / crate::math::sqrt(norm2);
        let umax = buf
            .mode
            .iter()
            .flatten()
            .fold(0.0, |m: Real, c| crate::math::max(m, crate::math::abs(*c)))
            * inv;
        let h = 1e-7 * size / umax;
        for sign in [1.0, -1.0] {
            for ((xp, xi), u) in buf.x_pert.iter_mut().zip(x).zip(buf.mode.iter()) {
                for a in 0..3 {
                    xp[a] = xi[a] + sign * h * u[a] * inv;
                }
            }
            buf.cp_scratch.copy_from_slice(cp_inv);
            let f = if sign > 0.0 {
                &mut *buf.f_plus
            } else {
                &mut *buf.f_minus
            };
            internal_forces(mesh, mat, settings, buf.x_pert, buf.cp_scratch, f).ok()?;
        }
        // y = M⁻¹ K u; Rayleigh quotient λ = uᵀ K u (u M-normalised).
        lambda = 0.0;
        for (((u, fp), fm), m) in buf
            .mode
            .iter_mut()
            .zip(buf.f_plus.iter())
            .zip(buf.f_minus.iter())
            .zip(mass)
        {
            for a in 0..3 {
                let ku = (fp[a] - fm[a]) / (2.0 * h);
                lambda += u[a] * inv * ku;
                u[a] = ku / m;
            }
        }
    }
    Some(crate::math::sqrt(crate::math::max(lambda, 0.0)))
}

/// How the stable time step is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeStepMethod {
    /// safety × min L_e / c_d, re-estimated every interval: simple and
    /// conservative by 1.3× on the undeformed sphere and by up to 2× once
    /// contact elements flatten.
    Element,
    /// safety × 2/ω_max from power iteration (warm-started, every
    /// `power_interval` re-estimates), scaled in between by how much
    /// min L_e has shrunk since the last power iteration (never enlarged).
    Global {
        /// Element re-estimates between power iterations; ≥ 1.
        power_interval: u32,
        /// Power iterations per re-estimate (the first uses 10× as many); ≥ 1.
        power_iterations: u32,
    },
}

/// The time-step policy of a granule and what it remembers between
/// re-estimates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeStepControl {
    method: TimeStepMethod,
    safety: Real,
    /// Element re-estimates since the last power iteration.
    since_power: u32,
    /// 2/ω_max at the last power iteration, s.
    global_dt: Real,
    /// min L_e at the last power iteration, m.
    global_length: Real,
}

/// Fills `mode` with the fixed, non-symmetric start field of the power
/// iteration (the same everywhere, so runs are reproducible).
pub fn power_start(mode: &mut [[Real; 3]]) {
    for (i, u) in mode.iter_mut().enumerate() {
        let k = i as Real;
        *u = [
            crate::math::sin(1.7 * k + 0.3),
            crate::math::cos(2.3 * k),
            crate::math::sin(0.7 * k + 1.1),
        ];
    }
}

/// What a [`TimeStepControl`] remembers between re-estimates, for
/// checkpoints: (re-estimates since the last power iteration, 2/ω_max then
/// in s, min L_e then in m).
pub type TimeStepMemory = (u32, Real, Real);

impl TimeStepControl {
    /// What the policy remembers (see [`TimeStepMemory`]).
    pub fn memory(&self) -> TimeStepMemory {
        (self.since_power, self.global_dt, self.global_length)
    }

    /// Continues with `memory` from [`Self::memory`].
    pub fn restore(&mut self, memory: TimeStepMemory) {
        (self.since_power, self.global_dt, self.global_length) = memory;
    }

    /// Tells the policy that every mass of its granule was multiplied by
    /// `factor` (variable mass scaling): M → kM scales every eigenvalue
    /// ω² of M⁻¹K by 1/k and leaves the modes as they are, so the
    /// remembered 2/ω_max grows by √k and the power iteration's warm start
    /// stays a mode. Returns false, changing nothing, for the element
    /// estimate (which does not see the masses) or a factor that is not
    /// finite and positive.
    pub fn scale_masses(&mut self, factor: Real) -> bool {
        let global = matches!(self.method, TimeStepMethod::Global { .. });
        let usable = factor > 0.0 && factor.is_finite();
        if global && usable {
            self.global_dt *= crate::math::sqrt(factor);
        }
        global && usable
    }

    /// A policy with safety factor `safety`: 0 < C ≤ 1 for a stable step;
    /// up to [`MAX_SAFETY`] to provoke an instability on purpose (a test of
    /// the watchdogs); [`Self::estimate`] gives no step outside (0, 2].
    pub fn new(method: TimeStepMethod, safety: Real) -> Self {
        Self {
            method,
            safety,
            since_power: 0,
            global_dt: 0.0,
            global_length: 0.0,
        }
    }

    /// The stable step for the granule at `at`, s; `None` if an element is
    /// inverted, the motion is not finite, the safety factor is not in
    /// (0, [`MAX_SAFETY`]] or a buffer of `power` has the wrong length. `power` is scratch for the
    /// global method (its `mode` is kept as the warm start between calls;
    /// fill it with any non-zero field before the first call).
    pub fn estimate(
        &mut self,
        mesh: &ReferenceMesh<'_>,
        mat: &Material,
        settings: &ElementSettings,
        at: &Linearisation<'_>,
        power: &mut PowerIterationBuffers<'_>,
    ) -> Option<Real> {
        if !(self.safety > 0.0 && self.safety <= MAX_SAFETY) {
            return None;
        }
        let length = min_element_length(mesh, at.x)?;
        let TimeStepMethod::Global {
            power_interval,
            power_iterations,
        } = self.method
        else {
            return Some(self.safety * length / wave_speed(mat));
        };
        if self.global_dt == 0.0 || self.since_power >= power_interval {
            let iterations = if self.global_dt == 0.0 {
                power_iterations.saturating_mul(10)
            } else {
                power_iterations
            };
            let omega = max_frequency(mesh, mat, settings, at, power, iterations)?;
            if omega.is_nan() || omega <= 0.0 {
                return None;
            }
            self.global_dt = 2.0 / omega;
            self.global_length = length;
            self.since_power = 0;
        }
        self.since_power += 1;
        let shrink = crate::math::min(1.0, length / self.global_length);
        Some(self.safety * self.global_dt * shrink)
    }
}
