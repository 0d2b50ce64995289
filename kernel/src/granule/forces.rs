//! Internal forces of one granule: every element of the shared reference
//! mesh evaluated at the granule's current positions, assembled into nodal
//! forces in element order (deterministic).

use core::fmt;

use crate::Real;
use crate::constitutive::{UpdateError, UpdateOptions};
use crate::element::force::hex_forces;
use crate::material::Material;
use crate::mesh::reference::ReferenceMesh;
use crate::tensor::{Voigt, deviator, norm, trace};

/// Element-loop settings of a granule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementSettings {
    /// Constitutive switches.
    pub update: UpdateOptions,
    /// Hourglass coefficient κ.
    pub hourglass_kappa: Real,
}

/// An element whose update failed, with the kernel's reason.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementFailure {
    /// Element index in the reference mesh.
    pub element: usize,
    /// What went wrong.
    pub error: UpdateError,
}

impl fmt::Display for ElementFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "element {}: {}", self.element, self.error)
    }
}

impl core::error::Error for ElementFailure {}

/// What an element pass measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceSummary {
    /// Hourglass energy Σ (k/2)Σ|q|², J.
    pub hourglass_energy: Real,
    /// Plastic dissipation of this step Σ V0 Δγ (2β² + ⅔ a1 α²), J.
    pub plastic_dissipation: Real,
    /// Smallest element J = det F̄.
    pub min_j: Real,
    /// Elements that yielded.
    pub plastic_elements: usize,
    /// Most return-map iterations of any element.
    pub max_iterations: u32,
    /// Elements whose a2 was clamped (η ≤ η_c).
    pub a2_clamped: usize,
}

/// Evaluates all elements at positions `x` (`[node][xyz]`, m) and writes the
/// assembled internal + hourglass force into `f` (`[node][xyz]`, N, zeroed
/// first). `cp_inv` holds one C_p⁻¹ per element (in/out).
///
/// Lengths: `x`, `f` = nodes; `cp_inv` = hexes (checked by the caller's
/// scene setup; a mismatch panics on indexing — see the crate's slice policy).
pub fn internal_forces(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    settings: &ElementSettings,
    x: &[[Real; 3]],
    cp_inv: &mut [Voigt],
    f: &mut [[Real; 3]],
) -> Result<ForceSummary, ElementFailure> {
    f.fill([0.0; 3]);
    let mut s = ForceSummary {
        min_j: Real::INFINITY,
        ..ForceSummary::default()
    };
    for (element, ((hex, r), c)) in mesh
        .mesh
        .hexes
        .iter()
        .zip(mesh.elements.iter())
        .zip(cp_inv.iter_mut())
        .enumerate()
    {
        let xe = core::array::from_fn(|i| x[hex[i] as usize]);
        let out = hex_forces(mat, &settings.update, settings.hourglass_kappa, r, &xe, c)
            .map_err(|error| ElementFailure { element, error })?;
        for (id, fe) in hex.iter().zip(out.f.iter()) {
            let fi = &mut f[*id as usize];
            fi[0] += fe[0];
            fi[1] += fe[1];
            fi[2] += fe[2];
        }
        s.hourglass_energy += out.hourglass_energy;
        s.min_j = crate::math::min(s.min_j, out.j);
        if out.info.plastic {
            let beta = norm(&deviator(&out.tau));
            let alpha = trace(&out.tau);
            s.plastic_dissipation += r.volume
                * out.info.gamma
                * (2.0 * beta * beta + (2.0 / 3.0) * out.info.coefficients.a1 * alpha * alpha);
            s.plastic_elements += 1;
            s.max_iterations = s.max_iterations.max(out.info.iterations);
        }
        s.a2_clamped += usize::from(out.info.coefficients.a2_clamped);
    }
    Ok(s)
}

/// Stored elastic energy Σ_e V0 ψ(b^e, J^e) of a granule, J, with
/// b^e = F̄ C_p⁻¹ F̄ᵀ and J^e = det F̄ √det C_p⁻¹ per element.
pub fn elastic_energy(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    x: &[[Real; 3]],
    cp_inv: &[Voigt],
) -> Real {
    let mut energy = 0.0;
    for ((hex, r), c) in mesh
        .mesh
        .hexes
        .iter()
        .zip(mesh.elements.iter())
        .zip(cp_inv.iter())
    {
        let xe = core::array::from_fn(|i| x[hex[i] as usize]);
        let f = crate::element::force::mean_deformation_gradient(r, &xe);
        let be = crate::tensor::push_forward(&f, c);
        let je = crate::tensor::det_mat(&f) * crate::math::sqrt(crate::tensor::det(c));
        energy += r.volume * crate::constitutive::elastic::energy_density(mat, &be, je);
    }
    energy
}
