//! Nodal forces of the one-point, uniform-gradient, total-Lagrangian hex
//! with objective Flanagan–Belytschko hourglass stiffness (physics.md §2.1–§2.2).
//!
//! Per element: F̄ = Σ x_I ⊗ B0_I → constitutive update → P = τF̄⁻ᵀ →
//! f_I = V0 P B0_I; hourglass q_α = Σ x_I γ0_αI, k = κ(λ+2μ) V0 Σ|B0_I|²/3,
//! stiffening with the hourglass amplitude (see [`HOURGLASS_STIFFENING_AMPLITUDE`]):
//! f^hg_I = k Σ q_α (1 + |q_α|²/s²) γ0_αI, E_hg = Σ (k/2)|q_α|² (1 + |q_α|²/(2s²)).

use crate::Real;
use crate::constitutive::update::update_checked_state;
use crate::constitutive::{UpdateError, UpdateInfo, UpdateOptions};
use crate::element::hex8::HexCoords;
use crate::element::reference::HexReference;
use crate::lanes::Num;
use crate::material::Material;
use crate::tensor::{
    Mat3, Rows, Voigt, det_rows, from_rows, inverse_rows_with_det, rows_from_voigt,
};

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
    /// Kirchhoff stress at the element's point, Pa, Voigt order
    /// `[xx, yy, zz, yz, xz, xy]`, positive in tension.
    pub tau: Voigt,
    /// Constitutive diagnostics.
    pub info: UpdateInfo,
    /// Plastic dissipation of the step, V0 × the dissipation density, J.
    pub plastic_dissipation: Real,
}

/// Mean deformation gradient F̄ = Σ_I x_I ⊗ B0_I (exact for affine motion).
#[inline]
pub fn mean_deformation_gradient(r: &HexReference, x: &HexCoords) -> Mat3 {
    from_rows(&mean_gradient_rows(&r.b0, x))
}

/// [`mean_deformation_gradient`] as rows over any [`Num`]: F̄_ab summed over
/// the nodes in order from zero.
#[inline(always)]
pub fn mean_gradient_rows<T: Num>(b0: &[[T; 3]; 8], x: &[[T; 3]; 8]) -> Rows<T> {
    let mut f = [[T::splat(0.0); 3]; 3];
    for (xi, bi) in x.iter().zip(b0.iter()) {
        for (fa, &xa) in f.iter_mut().zip(xi) {
            for (fab, &bb) in fa.iter_mut().zip(bi) {
                *fab = *fab + xa * bb;
            }
        }
    }
    f
}

/// The reference data [`nodal_forces_into`] reads, as references so that the
/// scalar element borrows its [`HexReference`] and a batch its lanes.
#[derive(Clone, Copy, Debug)]
pub struct ElementGeometry<'a, T> {
    /// V0, m³.
    pub volume: T,
    /// B0_I, `[node][xyz]`, 1/m.
    pub b0: &'a [[T; 3]; 8],
    /// γ0_αI, `[mode][node]`.
    pub gamma0: &'a [[T; 8]; 4],
    /// V0 Σ|B0_I|²/3, m.
    pub hourglass_geometry: T,
}

impl<'a> ElementGeometry<'a, Real> {
    /// The geometry of one element.
    #[inline(always)]
    pub fn of(r: &'a HexReference) -> Self {
        Self {
            volume: r.volume,
            b0: &r.b0,
            gamma0: &r.gamma0,
            hourglass_geometry: r.hourglass_geometry,
        }
    }
}

/// Nodal forces f_I = V0 τ F̄⁻ᵀ B0_I plus the stiffening hourglass forces, for
/// nodes at `x` with F̄ = `f` (J = `j`) and Kirchhoff stress `tau`, written
/// into `out` (`[node][xyz]`, N; every entry is overwritten); returns the
/// hourglass energy, J. `kappa_modulus` = κ(λ + 2μ), Pa. Over any [`Num`]:
/// one element, or a batch of them side by side. The caller owns `out`: a
/// loop that keeps it from element to element spares the zeroing and the
/// copy of a returned array, which the compiler left in the batch loop as
/// calls of `memset` and `memcpy` (BENCHMARKS.md, session 31).
#[allow(non_snake_case)]
#[inline(always)]
pub fn nodal_forces_into<T: Num>(
    kappa_modulus: Real,
    g: &ElementGeometry<'_, T>,
    x: &[[T; 3]; 8],
    f: &Rows<T>,
    j: T,
    tau: &[T; 6],
    out: &mut [[T; 3]; 8],
) -> T {
    // P = V0 τ F⁻ᵀ: (τ F⁻ᵀ)_ab = Σ_k τ_ak (F⁻¹)_bk, summed k = 0, 1, 2, then
    // scaled by V0; f_I = P B0_I. The products are written out: left to
    // nalgebra's generic `Mul`, whether they were inlined depended on how
    // rustc partitioned the crate (out of line they cost 5 % of a bed run).
    // Same summation order as nalgebra's, so the same bits.
    let t = rows_from_voigt(tau);
    let f_inv = inverse_rows_with_det(f, j);
    let mut P = [[T::splat(0.0); 3]; 3];
    for (Pa, ta) in P.iter_mut().zip(&t) {
        for (Pab, f_inv_b) in Pa.iter_mut().zip(&f_inv) {
            *Pab = (ta[0] * f_inv_b[0] + ta[1] * f_inv_b[1] + ta[2] * f_inv_b[2]) * g.volume;
        }
    }
    // Hourglass stiffness, stiffening with the amplitude.
    let k = T::splat(kappa_modulus) * g.hourglass_geometry;
    let amplitude = T::splat(HOURGLASS_STIFFENING_AMPLITUDE) * g.hourglass_geometry;
    let inv_s2 = T::splat(1.0) / (T::splat(32.0) * amplitude * amplitude);
    // The four modes side by side, one coordinate at a time: a pass over
    // the nodes per coordinate, four sums in registers (all twelve at once
    // left one of them in memory, a chain of loads and stores through the
    // loop: BENCHMARKS.md, session 37). Every sum runs in the order of the
    // mode-by-mode form (q_α over nodes 0…7; f_I over modes 0…3), so the
    // same bits.
    let mut q = [[T::splat(0.0); 3]; 4];
    for b in 0..3 {
        let mut qb = [T::splat(0.0); 4];
        for (i, xi) in x.iter().enumerate() {
            for (qab, gm) in qb.iter_mut().zip(g.gamma0) {
                *qab = *qab + xi[b] * gm[i];
            }
        }
        for (qa, qab) in q.iter_mut().zip(qb) {
            qa[b] = qab;
        }
    }
    let mut energy = T::splat(0.0);
    let mut kq = [[T::splat(0.0); 3]; 4];
    for (qa, kqa) in q.iter().zip(kq.iter_mut()) {
        let qq = qa[0] * qa[0] + qa[1] * qa[1] + qa[2] * qa[2];
        let ratio = qq * inv_s2;
        energy = energy + T::splat(0.5) * k * qq * (T::splat(1.0) + T::splat(0.5) * ratio);
        let stiffness = k * (T::splat(1.0) + ratio);
        for (kqab, &qab) in kqa.iter_mut().zip(qa) {
            *kqab = stiffness * qab;
        }
    }
    // Node by node, f_I = P B0_I and then its hourglass part, mode by mode,
    // summed in a local and stored once: added into `out` in place, every
    // term was stored back (the compiler could not tell `out` from γ0 once
    // inlined), 9 stores per node more (BENCHMARKS.md, session 37).
    for (i, (fi, bi)) in out.iter_mut().zip(g.b0.iter()).enumerate() {
        let mut sum = [T::splat(0.0); 3];
        for (sa, Pa) in sum.iter_mut().zip(&P) {
            *sa = Pa[0] * bi[0] + Pa[1] * bi[1] + Pa[2] * bi[2];
        }
        for (kqa, gm) in kq.iter().zip(g.gamma0) {
            for (sa, &kqab) in sum.iter_mut().zip(kqa) {
                *sa = *sa + kqab * gm[i];
            }
        }
        *fi = sum;
    }
    energy
}

/// Forces of one element at current node positions `x` (m).
///
/// * `cp_inv`: in/out, the element's C_p⁻¹ (start → end of step); untouched
///   on error. Symmetric positive definite, as the kernel's own returns
///   leave it: only its determinant is tested here, as in every element
///   path ([`crate::constitutive::update::check_state`] tests a state
///   loaded from elsewhere fully).
/// * `kappa`: hourglass coefficient κ (dimensionless, 0 ≤ κ ≤ 1; not
///   checked here, per element: [`crate::granule::forces::internal_forces`]
///   and the C ABI check it once per call — a NaN gives NaN forces).
/// * `r`: the element's reference data as
///   [`crate::element::reference::hex_reference`] makes it (which refuses
///   an inverted element). Not checked here either: a reference made by
///   hand with a non-finite volume or gradient gives non-finite forces;
///   the C ABI's `granbed_hex_forces` checks it.
///
/// [`crate::element::batch`] evaluates several elements side by side with
/// the same bits.
///
/// One point sees only the mean deformation F̄: an element folded by an
/// hourglass mode while F̄ stays regular (J > 0) is not an error here. The
/// smallest Gauss-point Jacobian ratio, which sees it, is
/// [`crate::granule::quality::worst_element`]'s (from reference
/// determinants taken once per mesh).
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
    let F = mean_gradient_rows(&r.b0, x);
    let up = update_checked_state(mat, opts, &F, cp_inv)?;
    let j = det_rows(&F);
    let mut f = [[0.0; 3]; 8];
    let hourglass_energy = nodal_forces_into(
        kappa * mat.p_wave_modulus(),
        &ElementGeometry::of(r),
        x,
        &F,
        j,
        &up.tau,
        &mut f,
    );
    Ok(HexForces {
        f,
        hourglass_energy,
        j,
        tau: up.tau,
        info: up.info,
        plastic_dissipation: r.volume * up.dissipation_density(),
    })
}
