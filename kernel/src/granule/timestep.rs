//! The stable time step of a granule (physics.md §4.2): Δt = C·min_e L_e/c_d,
//! L_e = V_e/A_e,max from the current geometry, c_d = √((λ+2μ)/ρ0).

use crate::Real;
use crate::element::hex8;
use crate::element::reference::hex_reference;
use crate::material::Material;
use crate::mesh::reference::ReferenceMesh;

/// Smallest characteristic length min_e V_e/A_e,max at positions `x` (m);
/// `None` if an element is inverted.
pub fn min_element_length(mesh: &ReferenceMesh<'_>, x: &[[Real; 3]]) -> Option<Real> {
    let mut min = Real::INFINITY;
    for hex in mesh.mesh.hexes {
        let xe = core::array::from_fn(|i| x[hex[i] as usize]);
        let volume = hex_reference(&xe)?.volume;
        min = crate::math::min(min, volume / hex8::max_face_area(&xe));
    }
    Some(min)
}

/// Dilatational wave speed c_d = √((λ+2μ)/ρ0), m/s.
pub fn wave_speed(mat: &Material) -> Real {
    crate::math::sqrt(mat.p_wave_modulus() / mat.density0)
}

/// Element estimate of the stable step, s: `safety` × min L_e / c_d;
/// `None` if an element is inverted.
pub fn element_time_step(
    mesh: &ReferenceMesh<'_>,
    mat: &Material,
    x: &[[Real; 3]],
    safety: Real,
) -> Option<Real> {
    Some(safety * min_element_length(mesh, x)? / wave_speed(mat))
}
