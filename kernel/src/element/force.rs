//! Nodal forces of the one-point, uniform-gradient, total-Lagrangian hex
//! with objective Flanagan–Belytschko hourglass stiffness (physics.md §2.1–§2.2).
//!
//! Per element: F̄ = Σ x_I ⊗ B0_I → constitutive update → P = τF̄⁻ᵀ →
//! f_I = V0 P B0_I; hourglass q_α = Σ x_I γ0_αI, k = κ(λ+2μ) V0 Σ|B0_I|²/3,
//! stiffening with the hourglass amplitude (see [`HOURGLASS_STIFFENING_AMPLITUDE`]):
//! f^hg_I = k Σ q_α (1 + |q_α|²/s²) γ0_αI, E_hg = Σ (k/2)|q_α|² (1 + |q_α|²/(2s²)).

use crate::Real;
use crate::constitutive::{UpdateError, UpdateInfo, UpdateOptions, update_point};
use crate::element::hex8::HexCoords;
use crate::element::reference::HexReference;
use crate::material::Material;
use crate::tensor::{Mat3, Voigt, inverse_with_det, mat_from_voigt};

/// Default hourglass coefficient κ (physics.md §2.2: range 0.02–0.1).
pub const DEFAULT_HOURGLASS_KAPPA: Real = 0.05;

/// Hourglass amplitude (nodal hourglass displacement over the element
/// size) at which the hourglass stiffness has doubled; it grows with the
/// square of the amplitude, as the gradient of the quartic energy term.
///
/// **Deviation from physics.md §2.2 (linear FB stiffness), by
/// measurement:** with the linear form a C3 bed at 57.5 % strain folded an
/// element (a Gauss-point Jacobian reached −0.02 while the centre's stayed
/// at 0.77: the one-point element cannot see it), and raising κ to 0.1
/// instead stiffened a B2 bed by 6 % against the F-bar element at 30 %
/// (κ = 0.05 is within 1.6 % of it). The quartic term leaves the small
/// amplitudes of ordinary runs at κ's stiffness (a 2 % amplitude adds 4 %
/// to the hourglass force) and stops a fold (×10 at 30 %). For a cube of
/// side L, |q_α| = √8 d for a nodal amplitude d and L = 2 V0Σ|B0_I|²/3, so
/// s² = 32 a² (V0Σ|B0_I|²/3)² with a this constant; the energy stays
/// conservative and objective.
pub const HOURGLASS_STIFFENING_AMPLITUDE: Real = 0.1;

/// Result of one element evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HexForces {
    /// Internal plus hourglass force of each node, `[node][xyz]`, N; the
    /// nodal equation of motion subtracts it (m a = f_ext − f).
    pub f: [[Real; 3]; 8],
    /// Hourglass energy Σ (k/2)|q_α|²(1 + |q_α|²/(2s²)), J.
    pub hourglass_energy: Real,
    /// J = det F̄ (current volume / reference volume).
    pub j: Real,
    /// Kirchhoff stress at the element's point, Pa.
    pub tau: Voigt,
    /// Constitutive diagnostics.
    pub info: UpdateInfo,
    /// Plastic dissipation of the step, V0 × the dissipation density, J.
    pub plastic_dissipation: Real,
}

/// Mean deformation gradient F̄ = Σ_I x_I ⊗ B0_I (exact for affine motion).
#[inline]
pub fn mean_deformation_gradient(r: &HexReference, x: &HexCoords) -> Mat3 {
    let mut f = Mat3::zeros();
    for (xi, bi) in x.iter().zip(r.b0.iter()) {
        for a in 0..3 {
            for b in 0..3 {
                f[(a, b)] += xi[a] * bi[b];
            }
        }
    }
    f
}

/// V0 τ F⁻ᵀ from τ, F⁻¹ and V0: (τ F⁻ᵀ)_ab = Σ_k τ_ak (F⁻¹)_bk, summed
/// k = 0, 1, 2, then scaled by V0.
#[inline(always)]
fn kirchhoff_to_first_pk(tau: &Mat3, f_inv: &Mat3, volume: Real) -> Mat3 {
    Mat3::from_fn(|a, b| {
        (tau[(a, 0)] * f_inv[(b, 0)] + tau[(a, 1)] * f_inv[(b, 1)] + tau[(a, 2)] * f_inv[(b, 2)])
            * volume
    })
}

/// Forces of one element at current node positions `x` (m).
///
/// * `cp_inv`: in/out, the element's C_p⁻¹ (start → end of step); untouched
///   on error.
/// * `kappa`: hourglass coefficient κ (dimensionless).
#[allow(non_snake_case)]
#[inline]
pub fn hex_forces(
    mat: &Material,
    opts: &UpdateOptions,
    kappa: Real,
    r: &HexReference,
    x: &HexCoords,
    cp_inv: &mut Voigt,
) -> Result<HexForces, UpdateError> {
    let F = mean_deformation_gradient(r, x);
    let up = update_point(mat, opts, &F, cp_inv)?;
    let j = crate::tensor::det_mat(&F);
    // P = τ F⁻ᵀ; f_I = V0 P B0_I. The products are written out: left to
    // nalgebra's generic `Mul`, whether they were inlined depended on how
    // rustc partitioned the crate (out of line they cost 5 % of a bed run).
    // Same summation order as nalgebra's, so the same bits.
    let P = kirchhoff_to_first_pk(&mat_from_voigt(&up.tau), &inverse_with_det(&F, j), r.volume);
    let mut f = [[0.0; 3]; 8];
    for (fi, bi) in f.iter_mut().zip(r.b0.iter()) {
        for a in 0..3 {
            fi[a] = P[(a, 0)] * bi[0] + P[(a, 1)] * bi[1] + P[(a, 2)] * bi[2];
        }
    }
    // Hourglass stiffness, stiffening with the amplitude.
    let k = kappa * mat.p_wave_modulus() * r.hourglass_geometry;
    let amplitude = HOURGLASS_STIFFENING_AMPLITUDE * r.hourglass_geometry;
    let inv_s2 = 1.0 / (32.0 * amplitude * amplitude);
    // The four modes side by side: one pass over the nodes for all q_α,
    // one for all forces. Every sum runs in the order of the mode-by-mode
    // form (q_α over nodes 0…7; f_I over modes 0…3), so the same bits.
    let mut q = [[0.0; 3]; 4];
    for (i, xi) in x.iter().enumerate() {
        for (qa, g) in q.iter_mut().zip(&r.gamma0) {
            for a in 0..3 {
                qa[a] += xi[a] * g[i];
            }
        }
    }
    let mut energy = 0.0;
    let mut kq = [[0.0; 3]; 4];
    for (qa, kqa) in q.iter().zip(kq.iter_mut()) {
        let qq = qa[0] * qa[0] + qa[1] * qa[1] + qa[2] * qa[2];
        let ratio = qq * inv_s2;
        energy += 0.5 * k * qq * (1.0 + 0.5 * ratio);
        let stiffness = k * (1.0 + ratio);
        for a in 0..3 {
            kqa[a] = stiffness * qa[a];
        }
    }
    for (i, fi) in f.iter_mut().enumerate() {
        for (kqa, g) in kq.iter().zip(&r.gamma0) {
            for a in 0..3 {
                fi[a] += kqa[a] * g[i];
            }
        }
    }
    Ok(HexForces {
        f,
        hourglass_energy: energy,
        j,
        tau: up.tau,
        info: up.info,
        plastic_dissipation: r.volume * up.dissipation_density(),
    })
}
