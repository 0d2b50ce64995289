//! The 2×2×2 F-bar hexahedron (de Souza Neto et al. 1996), the verification
//! element of physics.md §2.3: full integration without volumetric locking,
//! no hourglass control, eight integration points (eight C_p⁻¹ states).
//!
//! At each Gauss point F̄_g = (J̄/J_g)^{1/3} F_g, with the mean dilatation
//! J̄ = v/V0 (current over reference element volume, both exact by the 2×2×2
//! rule). The nodal forces are the exact variation of Σ_g det J_g ψ(F̄_g):
//! f_I = Σ_g det J_g [τ̄_g b_Ig + ⅓ tr τ̄_g (b̄_I − b_Ig)],
//! b_Ig = F_g⁻ᵀ ∇_X N_I(ξ_g), b̄_I = (1/v) Σ_g det J_g J_g b_Ig.
//!
//! **Choice:** physics.md §2.3 allows J at the element centre or the mean
//! dilatation; the centre value fails the patch test on distorted elements
//! (the volumetric term ⅓ tr τ Σ_e V_e ∇N_I(0) does not cancel at an interior
//! node), the mean dilatation passes it exactly.
//!
//! Reference gradients are recomputed from the reference coordinates each
//! call (the parent-space gradients at the Gauss points come from
//! [`hex8::GAUSS_GRADIENTS`]): this element is for verification, not speed.

use crate::Real;
use crate::constitutive::{UpdateError, UpdateOptions, update_point};
use crate::element::hex8::{self, HexCoords};
use crate::material::Material;
use crate::tensor::{Mat3, Voigt, det_mat, inverse_with_det, mat_from_voigt, trace};

/// Aggregate result of one F-bar element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FbarForces {
    /// Internal force of each node, `[node][xyz]`, N (m a = f_ext − f).
    pub f: [[Real; 3]; 8],
    /// Smallest Gauss-point J.
    pub min_j: Real,
    /// Gauss points that yielded.
    pub plastic_points: usize,
    /// Most return-map iterations of any point.
    pub max_iterations: u32,
    /// Points whose a2 was clamped.
    pub a2_clamped: usize,
    /// Plastic dissipation of the step, J.
    pub plastic_dissipation: Real,
}

/// Reference gradients ∇_X N_I and det J at the Gauss point whose
/// parent-space gradients are `dn` (a row of [`hex8::GAUSS_GRADIENTS`]).
fn reference_gradients(x_ref: &HexCoords, dn: &[[Real; 3]; 8]) -> Option<([[Real; 3]; 8], Real)> {
    let j = hex8::jacobian_from_gradients(x_ref, dn);
    let det = det_mat(&j);
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let inv_t = inverse_with_det(&j, det).transpose();
    let grads = core::array::from_fn(|i| {
        core::array::from_fn(|a| {
            inv_t[(a, 0)] * dn[i][0] + inv_t[(a, 1)] * dn[i][1] + inv_t[(a, 2)] * dn[i][2]
        })
    });
    Some((grads, det))
}

fn deformation_gradient(x: &HexCoords, grads: &[[Real; 3]; 8]) -> Mat3 {
    let mut f = Mat3::zeros();
    for (xi, g) in x.iter().zip(grads) {
        for a in 0..3 {
            for b in 0..3 {
                f[(a, b)] += xi[a] * g[b];
            }
        }
    }
    f
}

/// Spatial gradients b_I = F⁻ᵀ ∇_X N_I.
fn spatial_gradients(f_inv_t: &Mat3, grads: &[[Real; 3]; 8]) -> [[Real; 3]; 8] {
    core::array::from_fn(|i| {
        let g = grads[i];
        core::array::from_fn(|a| {
            f_inv_t[(a, 0)] * g[0] + f_inv_t[(a, 1)] * g[1] + f_inv_t[(a, 2)] * g[2]
        })
    })
}

/// Per-Gauss-point kinematics of one element.
struct Kinematics {
    /// F_g.
    f: [Mat3; 8],
    /// J_g = det F_g.
    j: [Real; 8],
    /// det J_g of the reference map (the Gauss weight is 1).
    det_ref: [Real; 8],
    /// Spatial gradients b_Ig.
    b: [[[Real; 3]; 8]; 8],
    /// Mean dilatation J̄ = v/V0.
    j_bar: Real,
    /// Volume-weighted mean spatial gradients b̄_I.
    b_bar: [[Real; 3]; 8],
}

fn kinematics(x_ref: &HexCoords, x: &HexCoords) -> Result<Kinematics, UpdateError> {
    let mut k = Kinematics {
        f: [Mat3::zeros(); 8],
        j: [0.0; 8],
        det_ref: [0.0; 8],
        b: [[[0.0; 3]; 8]; 8],
        j_bar: 0.0,
        b_bar: [[0.0; 3]; 8],
    };
    let (mut v, mut v0) = (0.0, 0.0);
    for (g, dn) in hex8::GAUSS_GRADIENTS.iter().enumerate() {
        let (grads, det_ref) =
            reference_gradients(x_ref, dn).ok_or(UpdateError::InvertedDeformation { j: 0.0 })?;
        let f = deformation_gradient(x, &grads);
        let j = det_mat(&f);
        if j.is_nan() || j <= 0.0 {
            return Err(UpdateError::InvertedDeformation { j });
        }
        k.b[g] = spatial_gradients(&inverse_with_det(&f, j).transpose(), &grads);
        for i in 0..8 {
            for a in 0..3 {
                k.b_bar[i][a] += det_ref * j * k.b[g][i][a];
            }
        }
        (k.f[g], k.j[g], k.det_ref[g]) = (f, j, det_ref);
        v += det_ref * j;
        v0 += det_ref;
    }
    for bi in k.b_bar.iter_mut() {
        for c in bi.iter_mut() {
            *c /= v;
        }
    }
    k.j_bar = v / v0;
    Ok(k)
}

/// Forces of one F-bar element with reference coordinates `x_ref` at current
/// positions `x` (m); `cp_inv[g]` is the C_p⁻¹ of Gauss point g (in/out), in
/// [`crate::element::hex8::gauss_points`] order.
pub fn fbar_forces(
    mat: &Material,
    opts: &UpdateOptions,
    x_ref: &HexCoords,
    x: &HexCoords,
    cp_inv: &mut [Voigt; 8],
) -> Result<FbarForces, UpdateError> {
    let k = kinematics(x_ref, x)?;
    let mut out = FbarForces {
        f: [[0.0; 3]; 8],
        min_j: k
            .j
            .iter()
            .fold(Real::INFINITY, |m, &j| crate::math::min(m, j)),
        plastic_points: 0,
        max_iterations: 0,
        a2_clamped: 0,
        plastic_dissipation: 0.0,
    };
    for (g, state) in cp_inv.iter_mut().enumerate() {
        let fbar = k.f[g] * crate::math::cbrt(k.j_bar / k.j[g]);
        let up = update_point(mat, opts, &fbar, state)?;
        let tau = mat_from_voigt(&up.tau);
        let third_trace = trace(&up.tau) / 3.0;
        for ((fi, bi), bbar) in out.f.iter_mut().zip(&k.b[g]).zip(&k.b_bar) {
            for a in 0..3 {
                let full = tau[(a, 0)] * bi[0] + tau[(a, 1)] * bi[1] + tau[(a, 2)] * bi[2];
                fi[a] += k.det_ref[g] * (full + third_trace * (bbar[a] - bi[a]));
            }
        }
        if up.info.plastic {
            out.plastic_points += 1;
            out.max_iterations = out.max_iterations.max(up.info.iterations);
        }
        out.a2_clamped += usize::from(up.info.coefficients.a2_clamped);
        out.plastic_dissipation += k.det_ref[g] * up.dissipation_density();
    }
    Ok(out)
}

/// Cauchy stress of one F-bar element at current positions `x` (m), Pa,
/// Voigt `[xx, yy, zz, yz, xz, xy]`, positive in tension, and its volume
/// ratio J̄ = v/V0: each Gauss point's τ_g updated from a copy of its C_p⁻¹
/// (`cp_inv` is read, not changed), and σ = Σ_g det J_g^ref τ_g / (J̄ V0),
/// V0 = Σ_g det J_g^ref. F-bar gives every point the volume det J_g^ref J̄
/// (det F̄_g = J̄), so this is the volume average of σ_g = τ_g/J̄, and σ v is
/// the element's virial Σ_I x_I ⊗ f_I ([`fbar_forces`]: its b̄ term sums to
/// zero), as for the one-point element.
pub fn fbar_stress(
    mat: &Material,
    opts: &UpdateOptions,
    x_ref: &HexCoords,
    x: &HexCoords,
    cp_inv: &[Voigt; 8],
) -> Result<(Voigt, Real), UpdateError> {
    let k = kinematics(x_ref, x)?;
    let mut sum = [0.0; 6];
    let mut v0 = 0.0;
    for (g, state) in cp_inv.iter().enumerate() {
        let fbar = k.f[g] * crate::math::cbrt(k.j_bar / k.j[g]);
        let up = update_point(mat, opts, &fbar, &mut state.clone())?;
        for (s, t) in sum.iter_mut().zip(&up.tau) {
            *s += k.det_ref[g] * t;
        }
        v0 += k.det_ref[g];
    }
    Ok((sum.map(|s| s / (v0 * k.j_bar)), k.j_bar))
}

/// Stored elastic energy Σ_g det J_g ψ(F̄_g, C_p⁻¹_g) of one F-bar element, J
/// (0 if the element is inverted).
pub fn fbar_elastic_energy(
    mat: &Material,
    x_ref: &HexCoords,
    x: &HexCoords,
    cp_inv: &[Voigt; 8],
) -> Real {
    let Ok(k) = kinematics(x_ref, x) else {
        return 0.0;
    };
    let mut energy = 0.0;
    for (g, state) in cp_inv.iter().enumerate() {
        let fbar = k.f[g] * crate::math::cbrt(k.j_bar / k.j[g]);
        energy += k.det_ref[g] * crate::constitutive::elastic::energy_density_of(mat, &fbar, state);
    }
    energy
}
