//! The density and stress through the compact in its radial × height
//! section. At each snapshot the die volume between the punches is cut
//! into [`RINGS`] coaxial rings of equal width (the first a disc about the
//! die's axis, the last against the die wall) and [`LAYERS`] layers of
//! equal height, and each cell gets its solid fraction and the volume
//! averages, over the whole cell, of its elements' axial stress −σ_zz and
//! lateral stress −(σ_xx + σ_yy)/2 (an element counts in the cell of its
//! centre; the room between the granules counts empty and unstressed).
//! That is the density map of a tablet that X-ray tomography or
//! sectioning measures and that die-compaction models are compared by:
//! with the die wall's friction holding the load back, a compact pressed
//! from above is usually densest at its top outer edge and loosest at its
//! bottom outer edge (Train 1956).
//!
//! Written as `vtk/density_map_<k>.csv` ([`MAP_COLUMNS`]: a row per cell,
//! layers bottom first, rings from the axis out within a layer), at every
//! snapshot (the pour's packing too, before the first step); the last
//! snapshot's map goes into `summary.json`'s `final_density_map`
//! ([`MapSummary`]), the report and `plots/density_map.svg`.
//!
//! **What must hold.** The cells tile the compact, so the map's solid
//! volume, Σ φ_cell V_cell, is the elements' solid volume N η0 V0
//! (elements outside the die or the punches, a contact's overlap, count in
//! the nearest cell), and each layer's cells, weighted by their volumes,
//! give that layer of the stress file (`vtk/stress_<k>.csv`,
//! [`super::stress_profile`]) — the tests hold the bed to both.
//!
//! Cells are small: in the published scene (die 11.3 mm, granules 1 mm)
//! the disc about the axis holds about three granules' volume, the ring
//! at the wall about thirty, so the map of one bed is noisy at the axis;
//! its rings at the wall and its layers are the better measured.

use std::path::Path;

use anyhow::Context as _;
use granbed_kernel::Real;
use serde::Serialize;

use super::snapshots::ElementFields;
pub use super::stress_profile::LAYERS;
use crate::csv::{Field, read_table, write_table};

/// Rings of equal width the compact is cut into.
pub const RINGS: usize = 5;

/// Columns of a map file, in order: (name, meaning with its unit).
pub const MAP_COLUMNS: [(&str, &str); 10] = [
    (
        "strain",
        "the snapshot's nominal axial strain C (the state is that of the step that first reached it)",
    ),
    (
        "inner",
        "the cell's inner radius, as a fraction of the die's radius R_d (0: the axis)",
    ),
    (
        "outer",
        "the cell's outer radius, as a fraction of R_d (1: the die wall)",
    ),
    (
        "bottom",
        "the cell's lower face, as a fraction of the compact's height H (0: the lower punch)",
    ),
    ("top", "the cell's upper face, as a fraction of H"),
    (
        "solid_fraction",
        "the solid volume of the elements whose centres lie in the cell (η0 V0 each) over the cell's volume π R_d² (outer² − inner²) H (top − bottom)",
    ),
    (
        "axial_stress_pa",
        "Σ −σ_zz v over the cell's elements (v each one's volume) over the cell's volume, Pa, positive in compression",
    ),
    (
        "lateral_stress_pa",
        "Σ −(σ_xx + σ_yy)/2 v over the cell's elements over the cell's volume, Pa, positive in compression",
    ),
    (
        "height_m",
        "the compact's height H between the punches at the snapshot, m",
    ),
    ("die_radius_m", "the die's radius R_d, m"),
];

/// One cell of a map.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MapCell {
    /// Inner radius, fraction of the die's radius.
    pub inner: Real,
    /// Outer radius, fraction of the die's radius.
    pub outer: Real,
    /// Lower face, fraction of the compact's height.
    pub bottom: Real,
    /// Upper face, fraction of the compact's height.
    pub top: Real,
    /// Solid volume over the cell's volume.
    pub solid_fraction: Real,
    /// Mean axial stress −σ_zz over the cell, Pa (compression positive).
    pub axial_stress_pa: Real,
    /// Mean lateral stress −(σ_xx + σ_yy)/2 over the cell, Pa.
    pub lateral_stress_pa: Real,
}

impl MapCell {
    /// The cell's volume in a die of radius `r` with the punches `h`
    /// apart, m³.
    pub fn volume_m3(&self, r: Real, h: Real) -> Real {
        core::f64::consts::PI
            * r
            * r
            * (self.outer * self.outer - self.inner * self.inner)
            * h
            * (self.top - self.bottom)
    }
}

/// The map of one snapshot: what its file holds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DensityMap {
    /// The snapshot's index k.
    pub snapshot: usize,
    /// Its nominal axial strain.
    pub strain: Real,
    /// The compact's height H between the punches, m.
    pub height_m: Real,
    /// The die's radius, m.
    pub die_radius_m: Real,
    /// [`RINGS`] × [`LAYERS`] cells, layers bottom first, rings from the
    /// axis out within a layer.
    pub cells: Vec<MapCell>,
}

/// The sums Σ v η, Σ v (−σ_zz), Σ v (−(σ_xx + σ_yy)/2) over the elements
/// of `fields` in each of `rings` (at least 1) × [`LAYERS`] cells (index
/// `layer * rings + ring`) of a die of radius `die_radius_m` with the
/// punches `height_m` apart, the lower one at z = 0. A cell holds its
/// lower and inner bounds, not its upper and outer ones. An element whose
/// centre lies outside the compact counts in the nearest cell, one with a
/// NaN or missing position in the bottom cell at the axis; NaN values
/// make their cell's sums NaN. With one ring these are the layers of the
/// stress file (the radii not read).
pub fn cell_sums(
    fields: &ElementFields,
    die_radius_m: Real,
    height_m: Real,
    rings: usize,
) -> Vec<[Real; 3]> {
    let rings = rings.max(1);
    let mut sums = vec![[0.0; 3]; rings * LAYERS];
    // `as` saturates: below 0 (and NaN) to 0, past the end to the count.
    let index = |x: Real, n: usize| ((x * n as Real).floor() as usize).min(n - 1);
    let at = |v: &[Real], e: usize| v.get(e).copied().unwrap_or(Real::NAN);
    for e in 0..fields.volume_m3.len() {
        let l = index(at(&fields.height_m, e) / height_m, LAYERS);
        let r = if rings == 1 {
            0
        } else {
            index(at(&fields.radius_m, e) / die_radius_m, rings)
        };
        let v = fields.volume_m3[e];
        let s = &mut sums[l * rings + r];
        s[0] += v * at(&fields.relative_density, e);
        s[1] += v * at(&fields.axial_stress_pa, e);
        s[2] += v * at(&fields.lateral_stress_pa, e);
    }
    sums
}

/// The map of the elements `fields` (all granules' elements, with their
/// volumes and centres' heights and radii) in a die of radius
/// `die_radius_m` whose punches are `height_m` apart, the lower one at
/// z = 0 (see [`cell_sums`]).
pub fn density_map(
    snapshot: usize,
    strain: Real,
    fields: &ElementFields,
    die_radius_m: Real,
    height_m: Real,
) -> DensityMap {
    let sums = cell_sums(fields, die_radius_m, height_m, RINGS);
    let cells = sums
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (l, r) = (i / RINGS, i % RINGS);
            let mut cell = MapCell {
                inner: r as Real / RINGS as Real,
                outer: (r + 1) as Real / RINGS as Real,
                bottom: l as Real / LAYERS as Real,
                top: (l + 1) as Real / LAYERS as Real,
                solid_fraction: 0.0,
                axial_stress_pa: 0.0,
                lateral_stress_pa: 0.0,
            };
            let v = cell.volume_m3(die_radius_m, height_m);
            cell.solid_fraction = s[0] / v;
            cell.axial_stress_pa = s[1] / v;
            cell.lateral_stress_pa = s[2] / v;
            cell
        })
        .collect();
    DensityMap {
        snapshot,
        strain,
        height_m,
        die_radius_m,
        cells,
    }
}

impl DensityMap {
    /// The file's rows, one per cell.
    fn rows(&self) -> impl Iterator<Item = [Field; 10]> + '_ {
        self.cells.iter().map(move |c| {
            [
                self.strain,
                c.inner,
                c.outer,
                c.bottom,
                c.top,
                c.solid_fraction,
                c.axial_stress_pa,
                c.lateral_stress_pa,
                self.height_m,
                self.die_radius_m,
            ]
            .map(Field::from)
        })
    }

    /// The map of snapshot `snapshot` from its file's rows (the strain
    /// and geometry are the first row's; every row repeats them).
    fn from_rows(snapshot: usize, rows: &[[Real; 10]; RINGS * LAYERS]) -> Self {
        let first = &rows[0];
        Self {
            snapshot,
            strain: first[0],
            height_m: first[8],
            die_radius_m: first[9],
            cells: rows
                .iter()
                .map(|r| MapCell {
                    inner: r[1],
                    outer: r[2],
                    bottom: r[3],
                    top: r[4],
                    solid_fraction: r[5],
                    axial_stress_pa: r[6],
                    lateral_stress_pa: r[7],
                })
                .collect(),
        }
    }

    /// The cell of ring `ring` (0 at the axis) in layer `layer` (0 at the
    /// lower punch).
    pub fn cell(&self, ring: usize, layer: usize) -> &MapCell {
        &self.cells[layer * RINGS + ring]
    }
}

/// File name of the map of snapshot `k`.
pub fn map_file(k: usize) -> String {
    format!("density_map_{k}.csv")
}

/// Writes `map` as `vtk_dir`/[`map_file`]`(map.snapshot)`.
pub fn write_map(vtk_dir: &Path, map: &DensityMap) -> anyhow::Result<()> {
    write_table(
        &vtk_dir.join(map_file(map.snapshot)),
        &MAP_COLUMNS,
        map.rows(),
    )
}

/// The maps' figures in `summary.json`: the last snapshot's map and where
/// it is densest and loosest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MapSummary {
    /// The map, as in its file.
    #[serde(flatten)]
    pub map: DensityMap,
    /// The cell of the largest solid fraction.
    pub densest: MapCell,
    /// The cell of the smallest solid fraction.
    pub loosest: MapCell,
    /// The solid fraction of the ring at the die wall, its upper half over
    /// its lower half (the mean of each half's layers, of equal volumes;
    /// `null` in JSON where the lower half is empty):
    /// above 1 where the wall's friction left the bottom outer edge looser
    /// than the top outer edge. Halves rather than the layers at the
    /// punches, which a flat punch leaves loose (spheres touch it at
    /// points) and which are thinner than a granule.
    pub wall_top_to_bottom: Real,
    /// The same for the disc about the axis.
    pub axis_top_to_bottom: Real,
}

impl MapSummary {
    /// The figures of `map` (`None` if a cell's solid fraction is NaN).
    pub fn of(map: &DensityMap) -> Option<Self> {
        if map.cells.iter().any(|c| c.solid_fraction.is_nan()) {
            return None;
        }
        let by_density = |a: &&MapCell, b: &&MapCell| a.solid_fraction.total_cmp(&b.solid_fraction);
        let densest = *map.cells.iter().max_by(by_density)?;
        let loosest = *map.cells.iter().min_by(by_density)?;
        let half = |ring, layers: core::ops::Range<usize>| {
            layers
                .map(|l| map.cell(ring, l).solid_fraction)
                .sum::<Real>()
        };
        let ratio = |ring| half(ring, LAYERS / 2..LAYERS) / half(ring, 0..LAYERS / 2);
        Some(Self {
            map: map.clone(),
            densest,
            loosest,
            wall_top_to_bottom: ratio(RINGS - 1),
            axis_top_to_bottom: ratio(0),
        })
    }
}

/// Width of a panel of the map's picture (the die's radius), px.
const PANEL: Real = 320.0;
/// Margins of a panel: left (the height's ticks), top (its title),
/// bottom (the radius's ticks), px; panels are [`PANEL`] + the left margin
/// + [`GAP`] apart.
const PANEL_MARGIN: [Real; 3] = [50.0, 50.0, 50.0];
/// Room between the panels, px.
const GAP: Real = 30.0;

/// The picture of `summary`'s map (`plots/density_map.svg`): the
/// half-section between the die's axis (left) and its wall (right), the
/// lower punch at the bottom, drawn to scale, in two panels — the solid
/// fraction and the axial stress, each cell coloured from its panel's
/// smallest value (dark) to its largest (yellow) and labelled with its
/// value. Without a map, a picture that says so.
pub fn map_svg(summary: Option<&MapSummary>) -> String {
    use core::fmt::Write as _;
    let Some(s) = summary else {
        return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"620\" height=\"60\">\
                <text x=\"10\" y=\"35\" font-family=\"sans-serif\" font-size=\"14\">\
                No density map: none in vtk/ (none written or readable), or a cell not finite.\
                </text></svg>\n"
            .to_owned();
    };

    let m = &s.map;
    let scale = PANEL / m.die_radius_m;
    let height = m.height_m * scale;
    let [left, top, bottom] = PANEL_MARGIN;
    let width = 2.0 * (left + PANEL) + GAP + 10.0;
    let total_height = top + height + bottom;
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width:.0}\" \
         height=\"{total_height:.0}\" font-family=\"sans-serif\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{:.0}\" y=\"20\" font-size=\"15\" text-anchor=\"middle\">The compact's \
         half-section at C = {:.3}: axis left, die wall right, lower punch below</text>\n",
        0.5 * width,
        m.strain
    );
    type Value = fn(&MapCell) -> Real;
    let panels: [(&str, Value, Real); 2] = [
        ("solid fraction", |c| c.solid_fraction, 1.0),
        ("axial stress −σzz, kPa", |c| c.axial_stress_pa, 1e-3),
    ];
    for (p, (title, value, unit)) in panels.into_iter().enumerate() {
        let x0 = left + p as Real * (left + PANEL + GAP);
        let (lo, hi) = m
            .cells
            .iter()
            .map(value)
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"42\" font-size=\"13\" text-anchor=\"middle\">{title} \
             ({:.3} to {:.3})</text>",
            x0 + 0.5 * PANEL,
            lo * unit,
            hi * unit
        );
        for c in &m.cells {
            let v = value(c);
            let t = if hi > lo { (v - lo) / (hi - lo) } else { 0.5 };
            let (x, w) = (x0 + c.inner * PANEL, (c.outer - c.inner) * PANEL);
            let (y, h) = (top + (1.0 - c.top) * height, (c.top - c.bottom) * height);
            let ink = if t > 0.6 { "black" } else { "white" };
            let _ = writeln!(
                svg,
                "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{w:.1}\" height=\"{h:.1}\" \
                 fill=\"{}\" stroke=\"white\" stroke-width=\"0.5\"/>\n\
                 <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" fill=\"{ink}\" \
                 text-anchor=\"middle\">{:.3}</text>",
                super::section::viridis(t),
                x + 0.5 * w,
                y + 0.5 * h + 3.5,
                v * unit
            );
        }
        let _ = writeln!(
            svg,
            "<rect x=\"{x0:.1}\" y=\"{top:.1}\" width=\"{PANEL:.1}\" height=\"{height:.1}\" \
             fill=\"none\" stroke=\"black\"/>\n\
             <line x1=\"{:.1}\" y1=\"{top:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\" \
             stroke-width=\"4\"/>",
            x0 + PANEL,
            x0 + PANEL,
            top + height
        );
        for i in 0..=RINGS {
            let f = i as Real / RINGS as Real;
            let _ = writeln!(
                svg,
                "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\">{f:.1}</text>",
                x0 + f * PANEL,
                top + height + 16.0
            );
        }
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\">r / R_d \
             (R_d = {:.2} mm)</text>",
            x0 + 0.5 * PANEL,
            top + height + 36.0,
            m.die_radius_m * 1e3
        );
        for l in [0, LAYERS / 2, LAYERS] {
            let f = l as Real / LAYERS as Real;
            let _ = writeln!(
                svg,
                "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"end\">{f:.1}</text>",
                x0 - 6.0,
                top + (1.0 - f) * height + 4.0
            );
        }
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\" \
             transform=\"rotate(-90 {:.1} {:.1})\">z / H (H = {:.2} mm)</text>",
            x0 - 30.0,
            top + 0.5 * height,
            x0 - 30.0,
            top + 0.5 * height,
            m.height_m * 1e3
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// The map of snapshot `k` from its file `path` (header and [`RINGS`] ×
/// [`LAYERS`] numeric rows checked).
fn read_map(k: usize, path: &Path) -> anyhow::Result<DensityMap> {
    let rows: [[Real; 10]; RINGS * LAYERS] = read_table(path, &MAP_COLUMNS)?
        .try_into()
        .map_err(|_| anyhow::anyhow!("`{}`: not {} rows", path.display(), RINGS * LAYERS))?;
    Ok(DensityMap::from_rows(k, &rows))
}

/// The figures of the last map file in `vtk_dir` (the largest k) for
/// `summary.json`'s `final_density_map`: `Ok(None)` without a map file;
/// an error naming the file if it cannot be read or a cell of its map is
/// not finite (an earlier snapshot's map does not stand in for it).
pub fn read_last(vtk_dir: &Path) -> anyhow::Result<Option<MapSummary>> {
    let Some((k, path)) = super::snapshots::numbered_files(vtk_dir, "density_map_", ".csv").pop()
    else {
        return Ok(None);
    };
    let map = read_map(k, &path)?;
    MapSummary::of(&map).map(Some).with_context(|| {
        format!(
            "`{}`: a cell's solid fraction is not finite (an element inverted?)",
            path.display()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Elements of 1 mm³ at (radius, height) with given axial stresses,
    /// relative density 0.5, lateral stress a tenth of the axial.
    fn fields(elements: &[(Real, Real, Real)]) -> ElementFields {
        let mut f = ElementFields::default();
        for &(r, z, axial) in elements {
            f.radius_m.push(r);
            f.height_m.push(z);
            f.volume_m3.push(1e-9);
            f.relative_density.push(0.5);
            f.axial_stress_pa.push(axial);
            f.lateral_stress_pa.push(0.1 * axial);
        }
        f
    }

    /// Each element in the cell of its centre, averaged over the whole
    /// cell's volume (a ring's volume grows with its radius); elements
    /// past the die wall or a punch count in the nearest cell; the cells
    /// tile the compact.
    #[test]
    fn elements_are_averaged_over_their_cells() {
        let (r, h) = (5e-3, 2e-3);
        let f = fields(&[
            (0.5e-3, 0.1e-3, 100.0),  // ring 0, layer 0
            (0.9e-3, -0.1e-3, 300.0), // ring 0, below the lower punch
            (4.5e-3, 1.95e-3, 50.0),  // ring 4, layer 9
            (5.2e-3, 2.3e-3, 70.0),   // past the wall and the upper punch
            (2.5e-3, 1.1e-3, 20.0),   // ring 2, layer 5
        ]);
        let m = density_map(1, 0.2, &f, r, h);
        assert_eq!(m.cells.len(), RINGS * LAYERS);
        let close = |a: Real, b: Real| (a - b).abs() <= 1e-12 * b.abs();
        let layer = h / LAYERS as Real;
        let pi = core::f64::consts::PI;
        let disc = pi * 1e-6 * layer;
        let wall = pi * (25e-6 - 16e-6) * layer;
        let c = m.cell(0, 0);
        assert_eq!((c.inner, c.outer, c.bottom, c.top), (0.0, 0.2, 0.0, 0.1));
        assert!(close(c.axial_stress_pa, 400e-9 / disc));
        assert!(close(c.lateral_stress_pa, 40e-9 / disc));
        assert!(close(c.solid_fraction, 1e-9 / disc));
        assert!(close(m.cell(4, 9).axial_stress_pa, 120e-9 / wall));
        let ring2 = pi * (9e-6 - 4e-6) * layer;
        assert!(close(m.cell(2, 5).axial_stress_pa, 20e-9 / ring2));
        assert_eq!(m.cell(1, 5).axial_stress_pa, 0.0);
        let solid: Real = m
            .cells
            .iter()
            .map(|c| c.solid_fraction * c.volume_m3(r, h))
            .sum();
        assert!(close(solid, 5.0 * 0.5e-9), "{solid}");
        let total: Real = m.cells.iter().map(|c| c.volume_m3(r, h)).sum();
        assert!(close(total, pi * r * r * h));
        // With one ring the sums are the stress file's layers.
        let one = cell_sums(&f, r, h, 1);
        for (got, want) in one[0].iter().zip([1e-9, 400e-9, 40e-9]) {
            assert!(close(*got, want), "{got} {want}");
        }
        // The summary: densest is the disc at the axis in layer 0.
        let s = MapSummary::of(&m).unwrap();
        assert_eq!(s.densest, *m.cell(0, 0));
        assert_eq!(s.loosest.solid_fraction, 0.0);
        // Ring 4 holds one element in its upper half, none in its lower;
        // the disc one in its lower half only.
        assert!(s.wall_top_to_bottom.is_infinite() && s.axis_top_to_bottom == 0.0);
        // A NaN element makes its cell NaN and the summary none.
        let nan = fields(&[(0.5e-3, 0.1e-3, Real::NAN)]);
        let mut nan = nan.clone();
        nan.relative_density[0] = Real::NAN;
        let m = density_map(0, 0.1, &nan, r, h);
        assert!(m.cell(0, 0).solid_fraction.is_nan() && m.cell(1, 0).solid_fraction == 0.0);
        assert_eq!(MapSummary::of(&m), None);
    }

    /// A cell holds its lower and inner bounds: an element exactly at
    /// r = 0.2 R_d lies in the second ring, one at z = H/2 in the sixth
    /// layer; one at the die wall or the upper punch in the last ring or
    /// layer; a NaN position in the bottom cell at the axis.
    #[test]
    fn the_bounds_belong_to_the_cell_above() {
        let f = fields(&[
            (0.2, 0.05, 1.0),
            (0.1, 0.5, 2.0),
            (1.0, 1.0, 4.0),
            (Real::NAN, Real::NAN, 8.0),
        ]);
        let m = density_map(0, 0.0, &f, 1.0, 1.0);
        let volume = |c: &MapCell| c.volume_m3(1.0, 1.0);
        let axial = |ring, layer| {
            let c = m.cell(ring, layer);
            c.axial_stress_pa * volume(c) / 1e-9
        };
        let close = |a: Real, b: Real| (a - b).abs() <= 1e-12 * b;
        assert!(close(axial(1, 0), 1.0));
        assert!(close(axial(0, 5), 2.0));
        assert!(close(axial(RINGS - 1, LAYERS - 1), 4.0));
        assert!(close(axial(0, 0), 8.0));
    }

    /// The last map written reads back to the same bits as the summary's
    /// (an earlier one does not stand in for it); a last file with a row
    /// missing, or with a cell not finite, is an error that names it; no
    /// file is no map.
    #[test]
    fn the_last_map_file_round_trips() {
        let dir = std::env::temp_dir().join(format!("granbed-map-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(read_last(&dir).unwrap(), None);
        let f = fields(&[(1.5e-3, 0.15e-3, 1.0 / 3.0), (0.2e-3, 0.75e-3, 2e3)]);
        let a = density_map(0, 0.0, &f, 2e-3, 1e-3);
        let b = density_map(3, 0.1 + 0.2, &f, 2e-3, 0.9e-3);
        write_map(&dir, &a).unwrap();
        write_map(&dir, &b).unwrap();
        // (Its ratios are 0/0 here: NaN, which no `==` holds.)
        let last = read_last(&dir).unwrap().unwrap();
        assert_eq!(
            (&last.map, last.densest),
            (&b, MapSummary::of(&b).unwrap().densest)
        );
        let text = std::fs::read_to_string(dir.join(map_file(0))).unwrap();
        let cut: String = text.lines().take(20).map(|l| format!("{l}\n")).collect();
        std::fs::write(dir.join(map_file(4)), cut).unwrap();
        let e = format!("{:#}", read_last(&dir).unwrap_err());
        assert!(e.contains("density_map_4.csv") && e.contains("rows"), "{e}");
        let mut nan = fields(&[(0.5e-3, 0.1e-3, 1.0)]);
        nan.relative_density[0] = Real::NAN;
        write_map(&dir, &density_map(4, 0.3, &nan, 2e-3, 1e-3)).unwrap();
        let e = format!("{:#}", read_last(&dir).unwrap_err());
        assert!(
            e.contains("density_map_4.csv") && e.contains("not finite"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
