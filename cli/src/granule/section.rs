//! `section.svg` and `section_density.svg` of `granbed-cli granule`: the
//! granule at the end of its run cut through its centre by the plane
//! y = 0, each hex coloured by its axial stress −σ_zz or its local relative
//! density η0/J, between the two platens ([`crate::bed::section`]).
//! An octant run is mirrored into the whole section: its copy in y < 0
//! (the plane y = 0 is one of its symmetry planes, whose hexes the cut
//! takes from the side below), turned into the four quarters ±x, ±z.

use granbed_kernel::Real;
use granbed_kernel::granule::forces::{ElementStress, element_stresses};
use granbed_kernel::scene::platens::{PlatenParams, Symmetry};

use super::run::RunResult;
use crate::bed::section::{Frame, Quantity, SectionInput, section_svg};
use crate::model::OwnedReference;

/// File name of the section picture coloured by axial stress.
pub const SECTION_SVG: &str = "section.svg";
/// File name of the section picture coloured by local relative density.
pub const DENSITY_SVG: &str = "section_density.svg";

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

/// The section pictures of `result`'s final state (run with `params` on
/// `mesh`), each as (file name, SVG text): [`SECTION_SVG`], coloured by the
/// axial stress, and [`DENSITY_SVG`], by the local relative density η0/J;
/// titled `title` and the quantity. None for a run that stopped on an
/// error (its last state is not one to show) or has no final state.
pub fn granule_sections(
    mesh: &OwnedReference,
    params: &PlatenParams,
    result: &RunResult,
    title: &str,
) -> anyhow::Result<Vec<(&'static str, String)>> {
    let (Some(last), None) = (result.samples.last(), &result.error) else {
        return Ok(Vec::new());
    };
    if result.final_x.is_empty() {
        return Ok(Vec::new());
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
    let eta0 = params.material.params.eta0;
    let copies = section_copies(&result.final_x, params.symmetry);
    let radius = result
        .final_x
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, Real::max);
    let picture = |quantity: Quantity, name: &str, of: fn(&ElementStress, Real) -> Real| {
        let values: Vec<Real> = stresses.iter().map(|s| of(s, eta0)).collect();
        let values = values.repeat(copies.len());
        section_svg(&SectionInput {
            granules: copies.iter().map(Vec::as_slice).collect(),
            hexes: &mesh.hexes,
            quads: &mesh.quads,
            values: &values,
            quantity,
            frame: Frame::Platens {
                half_width_m: 1.15 * radius,
                half_height_m: 0.5 * (result.diameter_m - last.approach_m),
            },
            title: format!("{title}: {name}"),
        })
    };
    Ok(vec![
        (
            SECTION_SVG,
            picture(Quantity::AxialStress, "axial stress −σzz", |s, _| {
                -s.sigma[2]
            }),
        ),
        (
            DENSITY_SVG,
            picture(
                Quantity::RelativeDensity,
                "local relative density η0/J",
                |s, eta0| eta0 / s.j,
            ),
        ),
    ])
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
