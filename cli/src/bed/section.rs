//! A picture without ParaView: a cross-section through the axis of
//! compression (the plane y = 0), each hex the plane cuts filled with its
//! axial stress −σ_zz (in a bed the force chains run where it is high),
//! the granules' outlines (their surface quads cut by the plane) drawn over
//! them, and the walls ([`Frame`]: die and punches, or two platens) around
//! them. The bed writes one as `vtk/section_<k>.svg` beside each VTU
//! snapshot (`snapshots.rs`), shown by `report.html`; `granbed-cli granule`
//! one of its final state (`granule/section`).
//!
//! The cut of a hex by the plane is the polygon through the points where
//! its twelve edges cross y = 0, in angular order about their centroid
//! (exact for a hex whose cut is convex, as for every hex that is not
//! folded).

use core::fmt::Write as _;

use granbed_kernel::Real;

/// The hex8 edges (corners 0–3 the bottom face, 4–7 the top, i + 4 above i).
const HEX_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (1, 2),
    (2, 3),
    (3, 0),
    (4, 5),
    (5, 6),
    (6, 7),
    (7, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// Width of the picture, px (its height follows the bed's aspect ratio).
const WIDTH: f64 = 900.0;
/// Margins: left, right (the colour bar), top (the title), bottom, px.
const MARGIN: [f64; 4] = [40.0, 110.0, 60.0, 40.0];

/// The points (x, z) where the segments `edges` of `corners` cross the
/// plane y = 0, each point once. A corner on the plane counts as on its
/// positive side (y ≥ 0), so that of two hexes sharing a face in the plane
/// only the one below it is cut (in that face), not both.
fn crossings(corners: &[[Real; 3]], edges: &[(usize, usize)]) -> Vec<[Real; 2]> {
    let mut points: Vec<[Real; 2]> = Vec::with_capacity(6);
    for &(a, b) in edges {
        let (pa, pb) = (corners[a], corners[b]);
        let (ya, yb) = (pa[1], pb[1]);
        if (ya >= 0.0) != (yb >= 0.0) {
            let t = ya / (ya - yb);
            let p = [pa[0] + t * (pb[0] - pa[0]), pa[2] + t * (pb[2] - pa[2])];
            if !points.contains(&p) {
                points.push(p);
            }
        }
    }
    points
}

/// The cut of the hex with `corners` (hex8 order) by the plane y = 0, as a
/// polygon (x, z) in angular order; `None` if the plane misses it or
/// touches it in fewer than three points.
pub fn cut_hex(corners: &[[Real; 3]; 8]) -> Option<Vec<[Real; 2]>> {
    let mut points = crossings(corners, &HEX_EDGES);
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as Real;
    let cx = points.iter().map(|p| p[0]).sum::<Real>() / n;
    let cz = points.iter().map(|p| p[1]).sum::<Real>() / n;
    let angle = |p: &[Real; 2]| (p[1] - cz).atan2(p[0] - cx);
    points.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
    Some(points)
}

/// The cut of a quad with `corners` by the plane y = 0: the segment (x, z)
/// it leaves, if it crosses the plane.
pub fn cut_quad(corners: &[[Real; 3]; 4]) -> Option<[[Real; 2]; 2]> {
    let points = crossings(corners, &[(0, 1), (1, 2), (2, 3), (3, 0)]);
    match points[..] {
        [a, b] => Some([a, b]),
        _ => None,
    }
}

/// The area of a polygon (shoelace), m² for points in m.
pub fn polygon_area(points: &[[Real; 2]]) -> Real {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<Real>()
        .abs()
}

/// Matplotlib's viridis at `t` ∈ [0, 1] (clamped; NaN gives grey), as
/// `#rrggbb`: nine of its colours, linearly between them.
pub fn viridis(t: Real) -> String {
    const STOPS: [[u8; 3]; 9] = [
        [0x44, 0x01, 0x54],
        [0x47, 0x2c, 0x7a],
        [0x3b, 0x51, 0x8b],
        [0x2c, 0x71, 0x8e],
        [0x21, 0x90, 0x8d],
        [0x27, 0xad, 0x81],
        [0x5c, 0xc8, 0x63],
        [0xaa, 0xdc, 0x32],
        [0xfd, 0xe7, 0x25],
    ];
    if t.is_nan() {
        return "#999999".to_owned();
    }
    let s = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as Real;
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as Real;
    let c: Vec<u8> = (0..3)
        .map(|k| {
            let (a, b) = (Real::from(STOPS[i][k]), Real::from(STOPS[i + 1][k]));
            (a + f * (b - a)).round() as u8
        })
        .collect();
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// A tension's colour at `t` ∈ [0, 1] (clamped): light to deep red.
pub fn tension_red(t: Real) -> String {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let mix = |a: Real, b: Real| (a + t * (b - a)).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        mix(251.0, 165.0),
        mix(180.0, 15.0),
        mix(180.0, 21.0)
    )
}

/// What a section picture shows.
pub struct SectionInput<'a> {
    /// Node positions of each granule, m.
    pub granules: Vec<&'a [[Real; 3]]>,
    /// The granules' hexes (one mesh for all), node indices.
    pub hexes: &'a [[u32; 8]],
    /// The granules' outer surface quads, node indices.
    pub quads: &'a [[u32; 4]],
    /// The value of each hex, `[granule][hex]` flattened, in the
    /// quantity's unit (Pa for a stress).
    pub values: &'a [Real],
    /// What `values` are.
    pub quantity: Quantity,
    /// What holds the granules.
    pub frame: Frame,
    /// The picture's title.
    pub title: String,
}

/// What the colours of a section show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Axial stress −σ_zz, Pa (positive in compression): the colours from
    /// 0 to the 99th percentile of the positive values.
    AxialStress,
    /// Local relative density η0/J: the colours from the 1st to the 99th
    /// percentile.
    RelativeDensity,
}

impl Quantity {
    /// The colour scale (lo, hi) of `values` (so that one extreme element
    /// does not wash the picture out).
    fn scale(self, values: impl Iterator<Item = Real>) -> (Real, Real) {
        match self {
            Quantity::AxialStress => (0.0, scale_top(values)),
            Quantity::RelativeDensity => {
                let v = sorted(values.filter(|v| v.is_finite()));
                let (lo, hi) = match (percentile(&v, 0.01), percentile(&v, 0.99)) {
                    (Some(lo), Some(hi)) => (lo, hi),
                    _ => (0.0, 1.0),
                };
                if hi - lo < 1e-3 {
                    (lo - 5e-4, hi + 5e-4)
                } else {
                    (lo, hi)
                }
            }
        }
    }

    /// The colour of `value` on the scale (lo, hi): viridis; an axial
    /// tension beyond 1 % of `hi` in reds instead, by its size against
    /// `hi` (a smaller one, round-off in an unloaded bed, is no load).
    fn colour(self, value: Real, lo: Real, hi: Real) -> String {
        match self {
            Quantity::AxialStress if value < -0.01 * hi => tension_red(-value / hi),
            _ => viridis((value - lo) / (hi - lo)),
        }
    }

    /// The colour bar's name, the value of its unit (Pa per kPa, say) for
    /// a scale up to `hi`, and the picture's footnote.
    fn legend(self, hi: Real) -> (String, Real, &'static str) {
        match self {
            Quantity::AxialStress => {
                let (unit, per) = scale_unit(hi);
                (
                    format!("−σzz, {unit}"),
                    per,
                    "darkest: no load; red: tension (its bar below); grey: no value; the scale ends at the 99th percentile",
                )
            }
            Quantity::RelativeDensity => (
                "η0/J".to_owned(),
                1.0,
                "the scale spans the 1st to the 99th percentile; grey: no value",
            ),
        }
    }
}

/// The walls around a section, which also set its extent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Frame {
    /// The die: its wall at |x| = `radius_m`, the punches at z = 0 and
    /// z = `upper_z_m`.
    Die {
        /// Die radius, m.
        radius_m: Real,
        /// Height of the upper punch above the lower, m.
        upper_z_m: Real,
    },
    /// Two platens at z = ±`half_height_m`, the picture ±`half_width_m`
    /// wide (a single granule).
    Platens {
        /// Half the picture's width, m.
        half_width_m: Real,
        /// The platens' distance from z = 0, m.
        half_height_m: Real,
    },
}

impl Frame {
    /// The picture's extent ([x_lo, x_hi], [z_lo, z_hi]), m.
    fn extent(&self) -> ([Real; 2], [Real; 2]) {
        match *self {
            Frame::Die {
                radius_m,
                upper_z_m,
            } => {
                let r = radius_m.max(Real::MIN_POSITIVE);
                ([-r, r], [0.0, upper_z_m.max(0.05 * r)])
            }
            Frame::Platens {
                half_width_m,
                half_height_m,
            } => {
                let w = half_width_m.max(Real::MIN_POSITIVE);
                (
                    [-w, w],
                    [-half_height_m.max(0.05 * w), half_height_m.max(0.05 * w)],
                )
            }
        }
    }
}

/// A scale bar for a picture `width` (m) wide: a power of ten at most a
/// quarter of it, and its label in mm or µm.
fn scale_bar(width: Real) -> (Real, String) {
    let bar = 10f64.powf((0.25 * width).log10().floor());
    let label = if bar >= 1e-3 {
        format!("{} mm", crate::numbers::short(bar * 1e3))
    } else {
        format!(
            "{} µm",
            crate::numbers::short((bar * 1e6 * 1e6).round() / 1e6)
        )
    };
    (bar, label)
}

/// The cut hexes of `input`: (polygon, axial stress).
fn cut_hexes(input: &SectionInput<'_>) -> Vec<(Vec<[Real; 2]>, Real)> {
    let per_granule = input.hexes.len();
    let mut out = Vec::new();
    for (g, x) in input.granules.iter().enumerate() {
        for (h, hex) in input.hexes.iter().enumerate() {
            if hex.iter().any(|&n| n as usize >= x.len()) {
                continue;
            }
            if let Some(polygon) = cut_hex(&hex.map(|n| x[n as usize])) {
                let value = input
                    .values
                    .get(g * per_granule + h)
                    .copied()
                    .unwrap_or(Real::NAN);
                out.push((polygon, value));
            }
        }
    }
    out
}

/// The top of the colour scale, Pa: the 99th percentile of the finite
/// positive stresses (so that one extreme element does not wash the
/// picture out), at least 1 Pa.
fn scale_top(values: impl Iterator<Item = Real>) -> Real {
    let v = sorted(values.filter(|v| v.is_finite() && *v > 0.0));
    percentile(&v, 0.99).map_or(1.0, |top| top.max(1.0))
}

/// `values` in ascending order.
fn sorted(values: impl Iterator<Item = Real>) -> Vec<Real> {
    let mut v: Vec<Real> = values.collect();
    v.sort_by(Real::total_cmp);
    v
}

/// The `q`-quantile of the ascending `sorted` (the nearest rank), or
/// `None` if it is empty.
fn percentile(sorted: &[Real], q: Real) -> Option<Real> {
    let last = sorted.len().checked_sub(1)?;
    sorted.get((last as Real * q).round() as usize).copied()
}

/// The colour bar's unit for a scale up to `vmax` Pa: kPa, or Pa below
/// 10 Pa (a bed not yet loaded); as (name, Pa per unit).
fn scale_unit(vmax: Real) -> (&'static str, Real) {
    if vmax < 10.0 {
        ("Pa", 1.0)
    } else {
        ("kPa", 1e3)
    }
}

/// A tick of the colour bar: `value` with the decimals that three
/// significant digits of the tick `step` need, the same for every tick.
fn tick_text(value: Real, step: Real) -> String {
    let decimals = if step > 0.0 && step.is_finite() {
        (2 - step.log10().floor() as i32).clamp(0, 6) as usize
    } else {
        0
    };
    format!("{value:.decimals$}")
}

/// The SVG text of the section picture of `input`.
pub fn section_svg(input: &SectionInput<'_>) -> String {
    let [left, right, top, bottom] = MARGIN;
    let ([x_lo, x_hi], [z_lo, z_hi]) = input.frame.extent();
    let scale = (WIDTH - left - right) / (x_hi - x_lo);
    let height = (top + bottom + scale * (z_hi - z_lo)).ceil();
    let px = |x: Real| left + scale * (x - x_lo);
    let pz = |z: Real| top + scale * (z_hi - z);
    let cuts = cut_hexes(input);
    let (lo, hi) = input.quantity.scale(cuts.iter().map(|c| c.1));
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{height}\" \
         viewBox=\"0 0 {WIDTH} {height}\" font-family=\"sans-serif\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{:.1}\" y=\"26\" font-size=\"18\" text-anchor=\"middle\">{}</text>",
        left + 0.5 * (WIDTH - left - right),
        crate::output::escape_markup(&input.title)
    );
    // The hexes, then the granules' outlines over them.
    for (polygon, value) in &cuts {
        let colour = input.quantity.colour(*value, lo, hi);
        let points: Vec<String> = polygon
            .iter()
            .map(|p| format!("{:.1},{:.1}", px(p[0]), pz(p[1])))
            .collect();
        let _ = writeln!(
            s,
            "<polygon points=\"{}\" fill=\"{colour}\" stroke=\"{colour}\" stroke-width=\"0.4\"/>",
            points.join(" ")
        );
    }
    let mut outline = String::new();
    for x in &input.granules {
        for quad in input.quads {
            let corners = quad.map(|n| x.get(n as usize).copied().unwrap_or([Real::NAN; 3]));
            if let Some([a, b]) = cut_quad(&corners) {
                let _ = write!(
                    outline,
                    "M{:.1},{:.1}L{:.1},{:.1}",
                    px(a[0]),
                    pz(a[1]),
                    px(b[0]),
                    pz(b[1])
                );
            }
        }
    }
    let _ = writeln!(
        s,
        "<path d=\"{outline}\" fill=\"none\" stroke=\"#222\" stroke-width=\"0.7\"/>"
    );
    // The punches or platens, and the die wall.
    let (x0, x1, z0, z1) = (
        px(x_lo) - 2.0,
        px(x_hi) + 2.0,
        pz(z_lo) + 2.0,
        pz(z_hi) - 2.0,
    );
    let _ = write!(
        s,
        "<g stroke=\"#555\" stroke-width=\"4\" fill=\"none\">\
         <line x1=\"{x0:.1}\" y1=\"{z0:.1}\" x2=\"{x1:.1}\" y2=\"{z0:.1}\"/>\
         <line x1=\"{x0:.1}\" y1=\"{z1:.1}\" x2=\"{x1:.1}\" y2=\"{z1:.1}\"/>"
    );
    if let Frame::Die { .. } = input.frame {
        let _ = write!(
            s,
            "<line x1=\"{x0:.1}\" y1=\"{z1:.1}\" x2=\"{x0:.1}\" y2=\"{z0:.1}\"/>\
             <line x1=\"{x1:.1}\" y1=\"{z1:.1}\" x2=\"{x1:.1}\" y2=\"{z0:.1}\"/>"
        );
    }
    let _ = writeln!(s, "</g>");
    // A scale bar under the picture.
    let (bar_m, bar_label) = scale_bar(x_hi - x_lo);
    let bar = bar_m * scale;
    let _ = writeln!(
        s,
        "<line x1=\"{left}\" y1=\"{0:.1}\" x2=\"{1:.1}\" y2=\"{0:.1}\" stroke=\"black\" stroke-width=\"2\"/>\
         <text x=\"{2:.1}\" y=\"{3:.1}\" font-size=\"13\">{bar_label}</text>",
        height - 18.0,
        left + bar,
        left + bar + 6.0,
        height - 13.0
    );
    // The colour bar; for the axial stress, the tension's reds under it,
    // from no load down to a tension as large as the bar's top.
    let (bx, by, full) = (WIDTH - right + 30.0, top, (height - top - bottom).max(60.0));
    let tension = input.quantity == Quantity::AxialStress;
    let bh = if tension { 0.75 * full } else { full };
    // A bar from `y` down `h` px in `steps` bands, each coloured at its
    // middle's fraction of the way down.
    let mut strip = |y: Real, h: Real, steps: u32, colour: &dyn Fn(Real) -> String| {
        for i in 0..steps {
            let _ = writeln!(
                s,
                "<rect x=\"{bx:.1}\" y=\"{:.1}\" width=\"18\" height=\"{:.2}\" fill=\"{}\"/>",
                y + h * Real::from(i) / Real::from(steps),
                h / Real::from(steps) + 0.5,
                colour((Real::from(i) + 0.5) / Real::from(steps))
            );
        }
    };
    // Largest at the top.
    strip(by, bh, 50, &|down| viridis(1.0 - down));
    let (ty, th) = (by + 0.8 * full, 0.2 * full);
    if tension {
        strip(ty, th, 20, &tension_red);
    }
    let (name, per_unit, footnote) = input.quantity.legend(hi);
    if tension {
        // Its one label at its foot (the footnote names the reds), a
        // quarter of the bar's height (at least 15 px) under the main
        // bar's 0.
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"13\">{}</text>",
            bx + 24.0,
            ty + th + 4.0,
            tick_text(-hi / per_unit, 0.25 * hi / per_unit)
        );
    }
    let step = 0.25 * (hi - lo) / per_unit;
    for i in 0..=4 {
        let f = i as Real / 4.0;
        let y = by + bh * (1.0 - f);
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"13\">{}</text>",
            bx + 24.0,
            y + 4.0,
            tick_text((lo + f * (hi - lo)) / per_unit, step)
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{bx:.1}\" y=\"{:.1}\" font-size=\"13\">{name}</text>\n\
         <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"end\">{footnote}</text>\n</svg>",
        by - 16.0,
        WIDTH - right,
        height - 13.0
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::MeshLevel;

    /// The cube [−1, 1]³ turned by `angle` about z, in hex8 order.
    fn cube(angle: Real) -> [[Real; 3]; 8] {
        let (c, s) = (angle.cos(), angle.sin());
        let base = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
        let mut out = [[0.0; 3]; 8];
        for (i, z) in [-1.0, 1.0].into_iter().enumerate() {
            for (j, [x, y]) in base.into_iter().enumerate() {
                out[4 * i + j] = [c * x - s * y, s * x + c * y, z];
            }
        }
        out
    }

    #[test]
    fn a_cube_cut_through_its_middle() {
        let square = cut_hex(&cube(0.0)).unwrap();
        assert_eq!(square.len(), 4);
        assert!((polygon_area(&square) - 4.0).abs() < 1e-12);
        // Turned by 45°, the plane cuts it along a diagonal: 2√2 by 2.
        let diagonal = cut_hex(&cube(core::f64::consts::FRAC_PI_4)).unwrap();
        assert!((polygon_area(&diagonal) - 4.0 * 2f64.sqrt()).abs() < 1e-12);
        // Turned by 30°: width 2/cos 30° (the plane crosses two faces).
        let turned = cut_hex(&cube(core::f64::consts::FRAC_PI_6)).unwrap();
        let width = 2.0 / (core::f64::consts::FRAC_PI_6).cos();
        assert!((polygon_area(&turned) - 2.0 * width).abs() < 1e-12);
        // Moved off the plane: no cut.
        let mut off = cube(0.3);
        for p in &mut off {
            p[1] += 3.0;
        }
        assert!(cut_hex(&off).is_none());
        let face = [
            [0.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 1.0, 1.0],
            [0.0, -1.0, 1.0],
        ];
        let [a, b] = cut_quad(&face).unwrap();
        assert_eq!([a, b], [[0.5, 0.0], [0.5, 1.0]]);
        // Two cubes sharing the face y = 0: only the one below is cut.
        let mut below = cube(0.0);
        let mut above = cube(0.0);
        for (p, q) in below.iter_mut().zip(&mut above) {
            p[1] -= 1.0;
            q[1] += 1.0;
        }
        assert!((polygon_area(&cut_hex(&below).unwrap()) - 4.0).abs() < 1e-12);
        assert!(cut_hex(&above).is_none());
    }

    /// The standard granule cut through its centre: the hexes' polygons
    /// tile the faceted great circle, whose area lies within the
    /// faceting's few per cent below πR² (0.983 of the sphere's volume
    /// on 8x2, README), and its outline is as long as about 2πR.
    #[test]
    fn a_granule_cut_through_its_centre_tiles_its_great_circle() {
        let r = 0.5e-3;
        let mesh = crate::model::OwnedReference::sphere(r, MeshLevel::new(8, 2), false).unwrap();
        let values = vec![1.0e3; mesh.hexes.len()];
        let input = SectionInput {
            granules: vec![&mesh.positions],
            hexes: &mesh.hexes,
            quads: &mesh.quads,
            values: &values,
            quantity: Quantity::AxialStress,
            frame: Frame::Platens {
                half_width_m: 0.6e-3,
                half_height_m: 0.5e-3,
            },
            title: "t".into(),
        };
        let cuts = cut_hexes(&input);
        let area: Real = cuts.iter().map(|c| polygon_area(&c.0)).sum();
        let circle = core::f64::consts::PI * r * r;
        assert!(
            area < circle && area > 0.97 * circle,
            "cut area {area:e} against πR² {circle:e}"
        );
        let outline: Real = mesh
            .quads
            .iter()
            .filter_map(|q| cut_quad(&q.map(|n| mesh.positions[n as usize])))
            .map(|[a, b]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt())
            .sum();
        let circumference = 2.0 * core::f64::consts::PI * r;
        assert!(
            (outline / circumference - 1.0).abs() < 0.02,
            "outline {outline:e} against 2πR {circumference:e}"
        );
        let svg = section_svg(&input);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("<polygon").count(), cuts.len());
    }

    #[test]
    fn colours_and_scale() {
        assert_eq!(viridis(0.0), "#440154");
        assert_eq!(viridis(1.0), "#fde725");
        assert_eq!(viridis(7.0), "#fde725");
        assert_eq!(viridis(-1.0), "#440154");
        assert_eq!(viridis(Real::NAN), "#999999");
        // Tension in reds, compression and no load in viridis.
        let q = Quantity::AxialStress;
        assert_eq!(q.colour(-1e3, 0.0, 1e3), "#a50f15");
        assert_eq!(q.colour(-1e9, 0.0, 1e3), "#a50f15");
        assert_eq!(q.colour(0.0, 0.0, 1e3), "#440154");
        assert_eq!(q.colour(-5.0, 0.0, 1e3), "#440154");
        assert_eq!(q.colour(1e3, 0.0, 1e3), "#fde725");
        assert_eq!(Quantity::RelativeDensity.colour(-1.0, 0.5, 1.0), "#440154");
        // One extreme element does not set the scale.
        let mut v: Vec<Real> = (1..=1000).map(Real::from).collect();
        v.push(1e9);
        assert_eq!(scale_top(v.into_iter()), 991.0);
        assert_eq!(scale_top([Real::NAN, -3.0].into_iter()), 1.0);
        // Ticks share their decimals: three digits of the step.
        let (unit, per) = scale_unit(43_200.0);
        assert_eq!((unit, per), ("kPa", 1e3));
        let ticks: Vec<String> = (0..=4)
            .map(|i| tick_text(Real::from(i) * 10.8, 10.8))
            .collect();
        assert_eq!(ticks, ["0.0", "10.8", "21.6", "32.4", "43.2"]);
        assert_eq!(scale_unit(1.0), ("Pa", 1.0));
        assert_eq!(tick_text(0.75, 0.25), "0.750");
        // Densities span their 1st to 99th percentile; a uniform field
        // still gets a scale.
        let rho: Vec<Real> = (0..=100).map(|i| 0.8 + 0.001 * Real::from(i)).collect();
        let (lo, hi) = Quantity::RelativeDensity.scale(rho.into_iter());
        assert!(
            (lo - 0.801).abs() < 1e-12 && (hi - 0.899).abs() < 1e-12,
            "{lo} {hi}"
        );
        let (lo, hi) = Quantity::RelativeDensity.scale([0.8; 5].into_iter());
        assert!(lo < 0.8 && hi > 0.8);
        // A scale bar a power of ten, named in mm or µm.
        assert_eq!(scale_bar(11.3e-3), (1e-3, "1 mm".to_owned()));
        assert_eq!(scale_bar(1.2e-3), (1e-4, "100 µm".to_owned()));
        assert_eq!(scale_bar(50e-3), (10e-3, "10 mm".to_owned()));
    }
}
