//! Reference-configuration data of one hex, computed once per element of the
//! canonical mesh and shared by every granule (physics.md §2.1–§2.2).

use crate::Real;
use crate::element::hex8::{self, HexCoords};
use crate::tensor::{Mat3, det_mat, inverse_with_det};

/// Normalised Flanagan–Belytschko hourglass base vectors ĥ_α = h_α/√8 in
/// node order (ηζ, ξζ, ξη and ξηζ patterns).
pub const HOURGLASS_BASE: [[Real; 8]; 4] = {
    const S: Real = 0.353_553_390_593_273_8; // 1/√8
    [
        [S, S, -S, -S, -S, -S, S, S],
        [S, -S, -S, S, -S, S, S, -S],
        [S, -S, S, -S, S, -S, S, -S],
        [-S, S, -S, S, S, -S, S, -S],
    ]
};

/// What one element of the reference mesh contributes, independent of the
/// material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HexReference {
    /// Reference volume V0 = Σ_g det J_g (exact for trilinear maps), m³.
    pub volume: Real,
    /// Mean gradients B0_I = (1/V0) ∫ ∇_X N_I dV, `[node][xyz]`, 1/m.
    pub b0: [[Real; 3]; 8],
    /// Hourglass shape vectors γ0_αI = ĥ_αI − (Σ_J ĥ_αJ X_J)·B0_I, `[mode][node]`.
    pub gamma0: [[Real; 8]; 4],
    /// Geometric hourglass factor V0 Σ_I |B0_I|² / 3, m; the stiffness is
    /// k = κ (λ + 2μ) times this.
    pub hourglass_geometry: Real,
    /// Lumped (row-sum) volume share of each node, Σ_g N_I det J_g, m³;
    /// the nodal mass is ρ0 times this.
    pub node_volume: [Real; 8],
}

impl HexReference {
    /// Whether the element forces can use this record: every entry
    /// finite, V0 > 0, every node volume > 0, and a hourglass geometry
    /// factor > 0 whose stiffening term 1/(32 (a·factor)²) (a =
    /// [`crate::element::force::HOURGLASS_STIFFENING_AMPLITUDE`]) is finite
    /// — a factor of 0, or one below about 10⁻¹⁵³ m, made it infinite and
    /// the forces NaN. What [`hex_reference`] returns for a hex of
    /// reasonable size passes; a hex whose coordinates are so large that
    /// its volume overflows does not.
    pub fn usable(&self) -> bool {
        let a = crate::element::force::HOURGLASS_STIFFENING_AMPLITUDE * self.hourglass_geometry;
        let stiffening = 1.0 / (32.0 * a * a);
        self.volume > 0.0
            && self.volume.is_finite()
            && self.hourglass_geometry > 0.0
            && stiffening.is_finite()
            && self.node_volume.iter().all(|&v| v > 0.0 && v.is_finite())
            && self.b0.as_flattened().iter().all(|v| v.is_finite())
            && self.gamma0.as_flattened().iter().all(|v| v.is_finite())
            && self.hourglass_geometry.is_finite()
    }
}

/// The volume Σ_g det J_g of a hex at node positions `x` (m³, [`hex8`]
/// order) by 2×2×2 Gauss quadrature, exact for the trilinear map — the
/// [`HexReference::volume`] of [`hex_reference`] to the bit, without the
/// gradients (the time-step estimate needs only this, at every re-estimate). `None`
/// if a Gauss-point Jacobian is not positive.
pub fn hex_volume(x: &HexCoords) -> Option<Real> {
    let dets = gauss_determinants(x);
    if dets.iter().any(|d| d.is_nan() || *d <= 0.0) {
        return None;
    }
    Some(dets.iter().fold(0.0, |volume, det| volume + det))
}

/// det J_g of a hex at node positions `x` (m, [`hex8`] order) at its
/// 2×2×2 Gauss points, in [`hex8::gauss_points`] order, m³ (no sign
/// check): the determinants of the quadrature, of [`hex_volume`] and of the
/// worst-element check.
#[inline]
pub fn gauss_determinants(x: &HexCoords) -> [Real; 8] {
    hex8::GAUSS_GRADIENTS.map(|g| det_mat(&hex8::jacobian_from_gradients(x, &g)))
}

/// The Jacobian and its determinant at each of [`hex8::gauss_points`], in
/// their order; `None` if a determinant is not positive (or is NaN).
fn gauss_jacobians(x: &HexCoords) -> Option<[(Mat3, Real); 8]> {
    let mut out = [(Mat3::zeros(), 0.0); 8];
    for (slot, g) in out.iter_mut().zip(&hex8::GAUSS_GRADIENTS) {
        let j: Mat3 = hex8::jacobian_from_gradients(x, g);
        let det = det_mat(&j);
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        *slot = (j, det);
    }
    Some(out)
}

/// Computes the reference data of a hex with reference node positions `x`
/// (m, [`hex8`] order) by 2×2×2 Gauss quadrature, exact for the trilinear
/// map. Returns `None` if a Gauss-point Jacobian is not positive.
pub fn hex_reference(x: &HexCoords) -> Option<HexReference> {
    let mut volume = 0.0;
    let mut grad_sum = [[0.0; 3]; 8];
    let mut node_volume = [0.0; 8];
    let jacobians = gauss_jacobians(x)?;
    for ((g, dn), (j, det)) in hex8::gauss_points()
        .into_iter()
        .zip(&hex8::GAUSS_GRADIENTS)
        .zip(jacobians)
    {
        volume += det;
        // ∇_X N = J⁻ᵀ ∇_ξ N, weighted by det J: det J · J⁻ᵀ = cof(J).
        let inv_t = inverse_with_det(&j, det).transpose();
        let n = hex8::shape(g);
        for i in 0..8 {
            for a in 0..3 {
                grad_sum[i][a] += det
                    * (inv_t[(a, 0)] * dn[i][0]
                        + inv_t[(a, 1)] * dn[i][1]
                        + inv_t[(a, 2)] * dn[i][2]);
            }
            node_volume[i] += n[i] * det;
        }
    }
    let b0: [[Real; 3]; 8] =
        core::array::from_fn(|i| core::array::from_fn(|a| grad_sum[i][a] / volume));
    let gamma0 = core::array::from_fn(|mode| {
        let h = &HOURGLASS_BASE[mode];
        let hx: [Real; 3] = core::array::from_fn(|a| (0..8).map(|i| h[i] * x[i][a]).sum());
        core::array::from_fn(|i| h[i] - (hx[0] * b0[i][0] + hx[1] * b0[i][1] + hx[2] * b0[i][2]))
    });
    let b_norm2: Real = b0
        .iter()
        .map(|b| b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
        .sum();
    Some(HexReference {
        volume,
        b0,
        gamma0,
        hourglass_geometry: volume * b_norm2 / 3.0,
        node_volume,
    })
}
