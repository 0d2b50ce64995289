//! Geometry of a closed surface of bilinear quads: area and enclosed volume
//! (physics.md §7: α_SV and granule volume), both by 2×2 Gauss quadrature,
//! which integrates the enclosed volume exactly.

use crate::Real;
use crate::contact::quad::{Bilinear, cross, dot, norm};
use crate::element::hex8::GAUSS_2;

/// Area (m²) and volume flux ⅓∫x·n dA (m³) of one bilinear quad with nodes
/// `x` (m) counter-clockwise seen from outside.
pub fn quad_area_and_flux(x: &[[Real; 3]; 4]) -> (Real, Real) {
    let q = Bilinear::new(x);
    let (mut area, mut flux) = (0.0, 0.0);
    for (xi, eta) in [
        (-GAUSS_2, -GAUSS_2),
        (GAUSS_2, -GAUSS_2),
        (GAUSS_2, GAUSS_2),
        (-GAUSS_2, GAUSS_2),
    ] {
        let (t1, t2) = q.tangents(xi, eta);
        let n = cross(&t1, &t2);
        area += norm(&n);
        flux += dot(&q.at(xi, eta), &n) / 3.0;
    }
    (area, flux)
}

/// Total area (m²) and enclosed volume (m³) of the closed surface `quads`
/// (node ids into `positions`, m), summed in quad order.
pub fn area_and_volume(positions: &[[Real; 3]], quads: &[[u32; 4]]) -> (Real, Real) {
    let (mut area, mut volume) = (0.0, 0.0);
    for q in quads {
        let x = core::array::from_fn(|i| positions[q[i] as usize]);
        let (a, v) = quad_area_and_flux(&x);
        area += a;
        volume += v;
    }
    (area, volume)
}
