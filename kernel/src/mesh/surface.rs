//! Geometry of a closed surface of bilinear quads: area and enclosed volume
//! (physics.md §7: α_SV and granule volume), both by 2×2 Gauss quadrature,
//! which integrates the enclosed volume exactly.

use crate::Real;
use crate::element::hex8::GAUSS_2;

/// Area (m²) and volume flux ⅓∫x·n dA (m³) of one bilinear quad with nodes
/// `x` (m) counter-clockwise seen from outside.
pub fn quad_area_and_flux(x: &[[Real; 3]; 4]) -> (Real, Real) {
    // x(ξ,η) = c + ξ e1 + η e2 + ξη w.
    let comb = |s: [Real; 4]| -> [Real; 3] {
        core::array::from_fn(|a| {
            0.25 * (s[0] * x[0][a] + s[1] * x[1][a] + s[2] * x[2][a] + s[3] * x[3][a])
        })
    };
    let c = comb([1.0, 1.0, 1.0, 1.0]);
    let e1 = comb([-1.0, 1.0, 1.0, -1.0]);
    let e2 = comb([-1.0, -1.0, 1.0, 1.0]);
    let w = comb([1.0, -1.0, 1.0, -1.0]);
    let (mut area, mut flux) = (0.0, 0.0);
    for (xi, eta) in [
        (-GAUSS_2, -GAUSS_2),
        (GAUSS_2, -GAUSS_2),
        (GAUSS_2, GAUSS_2),
        (-GAUSS_2, GAUSS_2),
    ] {
        let t1: [Real; 3] = core::array::from_fn(|a| e1[a] + eta * w[a]);
        let t2: [Real; 3] = core::array::from_fn(|a| e2[a] + xi * w[a]);
        let n = [
            t1[1] * t2[2] - t1[2] * t2[1],
            t1[2] * t2[0] - t1[0] * t2[2],
            t1[0] * t2[1] - t1[1] * t2[0],
        ];
        let p: [Real; 3] =
            core::array::from_fn(|a| c[a] + xi * e1[a] + eta * e2[a] + xi * eta * w[a]);
        area += crate::math::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        flux += (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / 3.0;
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
