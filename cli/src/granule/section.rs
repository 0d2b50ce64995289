//! `section.svg` of `granbed-cli granule`: the granule at the end of its
//! run cut through its centre by the plane y = 0, each hex coloured by its
//! axial stress −σ_zz, between the two platens ([`crate::bed::section`]).
//! An octant run is mirrored into the whole section: its copy in y < 0
//! (the plane y = 0 is one of its symmetry planes, whose hexes the cut
//! takes from the side below), turned into the four quarters ±x, ±z.

use granbed_kernel::Real;
use granbed_kernel::granule::forces::{ElementStress, element_stresses};
use granbed_kernel::scene::platens::{PlatenParams, Symmetry};

use super::run::RunResult;
use crate::bed::section::{Frame, SectionInput, section_svg};
use crate::model::OwnedReference;

/// File name of the section picture in the output directory.
pub const SECTION_SVG: &str = "section.svg";

/// The granule's node positions as the section takes them: the whole
/// granule's `x` as it is, an octant's mirrored to y ≤ 0 and into the
/// four quarters (±x, ±z).
pub fn section_copies(x: &[[Real; 3]], symmetry: Symmetry) -> Vec<Vec<[Real; 3]>> {
    match symmetry {
        Symmetry::Full => vec![x.to_vec()],
        Symmetry::Octant => [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
            .iter()
            .map(|&(sx, sz)| x.iter().map(|p| [sx * p[0], -p[1], sz * p[2]]).collect())
            .collect(),
    }
}

/// The section picture of `result`'s final state (run with `params` on
/// `mesh`) titled `title`; `None` for a run that stopped on an error (its
/// last state is not one to show) or has no final state.
pub fn granule_section_svg(
    mesh: &OwnedReference,
    params: &PlatenParams,
    result: &RunResult,
    title: &str,
) -> anyhow::Result<Option<String>> {
    let (Some(last), None) = (result.samples.last(), &result.error) else {
        return Ok(None);
    };
    if result.final_x.is_empty() {
        return Ok(None);
    }
    let mut stresses = vec![ElementStress::default(); mesh.hexes.len()];
    element_stresses(
        &mesh.view(),
        &params.material,
        &params.elements,
        &result.final_x,
        &result.final_cp_inv,
        &mut stresses,
    )
    .map_err(|e| anyhow::anyhow!("the final state's element stresses: {e:?}"))?;
    let axial: Vec<Real> = stresses.iter().map(|s| -s.sigma[2]).collect();
    let copies = section_copies(&result.final_x, params.symmetry);
    let values: Vec<Real> = axial.repeat(copies.len());
    let radius = result
        .final_x
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, Real::max);
    let input = SectionInput {
        granules: copies.iter().map(Vec::as_slice).collect(),
        hexes: &mesh.hexes,
        quads: &mesh.quads,
        axial_stress_pa: &values,
        frame: Frame::Platens {
            half_width_m: 1.15 * radius,
            half_height_m: 0.5 * (result.diameter_m - last.approach_m),
        },
        title: title.to_owned(),
    };
    Ok(Some(section_svg(&input)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bed::section::{cut_hex, polygon_area};
    use crate::model::MeshLevel;

    /// The undeformed octant mirrored into the section tiles the same
    /// great circle as the whole granule: the plane y = 0 is the octant's
    /// face, which only its copy below cuts.
    #[test]
    fn a_mirrored_octant_cuts_as_the_whole_granule() {
        let r = 0.5e-3;
        let area = |mesh: &OwnedReference, symmetry| -> Real {
            section_copies(&mesh.positions, symmetry)
                .iter()
                .flat_map(|x| {
                    mesh.hexes.iter().filter_map(|h| {
                        cut_hex(&h.map(|n| x[n as usize])).map(|p| polygon_area(&p))
                    })
                })
                .sum()
        };
        let level = MeshLevel::new(8, 2);
        let octant = OwnedReference::sphere(r, level, true).unwrap();
        let full = OwnedReference::sphere(r, level, false).unwrap();
        let (a_octant, a_full) = (area(&octant, Symmetry::Octant), area(&full, Symmetry::Full));
        let circle = core::f64::consts::PI * r * r;
        assert!(a_full > 0.97 * circle && a_full < circle, "{a_full:e}");
        assert!(
            (a_octant / a_full - 1.0).abs() < 1e-9,
            "octant {a_octant:e} against full {a_full:e}"
        );
        // Unmirrored, the octant's face on the plane is not cut at all.
        let unmirrored: Real = octant
            .hexes
            .iter()
            .filter_map(|h| cut_hex(&h.map(|n| octant.positions[n as usize])))
            .map(|p| polygon_area(&p))
            .sum();
        assert_eq!(unmirrored, 0.0);
    }
}
