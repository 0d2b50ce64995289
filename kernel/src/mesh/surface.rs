//! Geometry of a closed surface of bilinear quads: area and enclosed volume
//! (physics.md §7: α_SV and granule volume), both by 2×2 Gauss quadrature,
//! which integrates the enclosed volume exactly.

use crate::Real;
use crate::contact::quad::{Bilinear, cross, dot, norm};
use crate::element::hex8::GAUSS_2;

/// The 2×2 Gauss points of a bilinear quad with the area vectors
/// x_ξ × x_η there (m², per unit parent area), in a fixed order.
fn gauss_area_vectors(q: &Bilinear) -> [([Real; 2], [Real; 3]); 4] {
    [
        (-GAUSS_2, -GAUSS_2),
        (GAUSS_2, -GAUSS_2),
        (GAUSS_2, GAUSS_2),
        (-GAUSS_2, GAUSS_2),
    ]
    .map(|(xi, eta)| {
        let (t1, t2) = q.tangents(xi, eta);
        ([xi, eta], cross(&t1, &t2))
    })
}

/// Area (m²) and volume flux ⅓∫x·n dA (m³) of one bilinear quad with nodes
/// `x` (m) counter-clockwise seen from outside.
pub fn quad_area_and_flux(x: &[[Real; 3]; 4]) -> (Real, Real) {
    let q = Bilinear::new(x);
    let (mut area, mut flux) = (0.0, 0.0);
    for ([xi, eta], n) in gauss_area_vectors(&q) {
        area += norm(&n);
        flux += dot(&q.at(xi, eta), &n) / 3.0;
    }
    (area, flux)
}

/// The area of [`quad_area_and_flux`] alone, to the bit (m²): the contact
/// forces take a node's tributary area every sweep.
pub fn quad_area(x: &[[Real; 3]; 4]) -> Real {
    let mut area = 0.0;
    for (_, n) in gauss_area_vectors(&Bilinear::new(x)) {
        area += norm(&n);
    }
    area
}

/// Total area (m²) and enclosed volume (m³) of the closed surface `quads`
/// (node ids into `positions`, m), summed in quad order; `None` if a quad
/// names a node beyond `positions`.
pub fn area_and_volume(positions: &[[Real; 3]], quads: &[[u32; 4]]) -> Option<(Real, Real)> {
    let (mut area, mut volume) = (0.0, 0.0);
    for q in quads {
        let mut x = [[0.0; 3]; 4];
        for (xi, &id) in x.iter_mut().zip(q) {
            *xi = *positions.get(id as usize)?;
        }
        let (a, v) = quad_area_and_flux(&x);
        area += a;
        volume += v;
    }
    Some((area, volume))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `quad_area` is `quad_area_and_flux`'s area to the bit (the contact
    /// forces' tributary areas use it), on warped and skewed quads.
    #[test]
    fn the_quad_area_is_the_area_of_area_and_flux_to_the_bit() {
        for k in 0..100 {
            let t = k as Real * 0.37;
            let x = [
                [0.0, 0.0, 0.1 * crate::math::sin(t)],
                [1.0 + 0.3 * crate::math::cos(t), 0.1, 0.0],
                [
                    1.2,
                    0.9 + 0.2 * crate::math::sin(2.0 * t),
                    0.2 * crate::math::cos(t),
                ],
                [0.1 * crate::math::sin(3.0 * t), 1.0, 0.0],
            ];
            assert_eq!(
                quad_area(&x).to_bits(),
                quad_area_and_flux(&x).0.to_bits(),
                "quad {x:?}"
            );
        }
    }
}
