//! The files `granbed-cli pack` writes: the packing (CSV, the hand-over
//! format to the bed compression), the summary JSON and the VTK view, and
//! the packing reader. Every writer and the reader name the file in their
//! errors.

use crate::output::{create_file, finish_file};
use std::path::Path;

use anyhow::{Context as _, bail};
use granbed_kernel::Real;

use super::summary::Summary;
use crate::csv::{CsvWriter, Field};
use crate::vtk::{Cells, DataArray, UnstructuredGrid, Values};

/// File name of the packing.
pub const PACKING_CSV: &str = "packing.csv";
/// File name of the pour summary.
pub const SUMMARY_JSON: &str = "summary.json";
/// File name of the VTK view of the packing.
pub const PACKING_VTU: &str = "packing.vtu";

/// Header of [`PACKING_CSV`]: centre and radius of each granule, m.
pub const PACKING_COLUMNS: [&str; 4] = ["x_m", "y_m", "z_m", "radius_m"];

/// One granule of a packing: centre (m) and radius (m).
pub type Sphere = ([Real; 3], Real);

/// Writes the packing, one row per granule in granule order, to `path`
/// ([`PACKING_COLUMNS`]; floats round-trip exact, so [`read_packing`]
/// gives back the same bits).
pub fn write_packing(path: &Path, centres: &[[Real; 3]], radius: Real) -> anyhow::Result<()> {
    let ctx = || format!("cannot write to `{}`", path.display());
    let mut csv = CsvWriter::new(create_file(path)?, &PACKING_COLUMNS).with_context(ctx)?;
    for c in centres {
        let row = [c[0], c[1], c[2], radius].map(Field::Real);
        csv.write_row(&row).with_context(ctx)?;
    }
    finish_file(csv.into_inner(), path)
}

/// Reads a packing written by `granbed-cli pack` ([`PACKING_CSV`]): the
/// centre and radius of every granule, in file order, bit for bit as
/// written.
///
/// The header must be `x_m,y_m,z_m,radius_m`; every row four finite
/// numbers with a positive radius; at least one row. Errors name the file
/// and the line.
pub fn read_packing(path: &Path) -> anyhow::Result<Vec<Sphere>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read packing `{}`", path.display()))?;
    parse_packing(&text).with_context(|| format!("packing `{}`", path.display()))
}

/// Parses the text of a packing file (see [`read_packing`]).
pub fn parse_packing(text: &str) -> anyhow::Result<Vec<Sphere>> {
    let mut lines = text.lines().map(|l| l.strip_suffix('\r').unwrap_or(l));
    let header = PACKING_COLUMNS.join(",");
    match lines.next() {
        Some(h) if h == header => {}
        Some(h) => bail!("line 1: header is `{h}`, expected `{header}`"),
        None => bail!("the file is empty, expected the header `{header}`"),
    }
    let mut spheres = Vec::new();
    for (k, line) in lines.enumerate() {
        let line_no = k + 2;
        let mut cells = [0.0; 4];
        let mut fields = line.split(',');
        for (cell, name) in cells.iter_mut().zip(PACKING_COLUMNS) {
            let field = fields
                .next()
                .with_context(|| format!("line {line_no}: no `{name}` value"))?;
            *cell = field
                .trim()
                .parse::<Real>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| {
                    format!("line {line_no}: `{name}` = `{field}` is not a finite number")
                })?;
        }
        if fields.next().is_some() {
            bail!("line {line_no}: more than {} values", PACKING_COLUMNS.len());
        }
        let [x, y, z, radius] = cells;
        if radius <= 0.0 {
            bail!("line {line_no}: radius_m = {radius} is not positive");
        }
        spheres.push(([x, y, z], radius));
    }
    if spheres.is_empty() {
        bail!("no granules (only the header)");
    }
    Ok(spheres)
}

/// Writes `summary` as pretty-printed JSON to `path` (see
/// [`crate::output::write_json`]).
pub fn write_summary_json(path: &Path, summary: &Summary) -> anyhow::Result<()> {
    crate::output::write_json(path, summary)
}

/// Writes the packing as a VTK unstructured grid to `path`: one
/// `VTK_VERTEX` per granule at its centre, with point data `radius` (m) and
/// `id` (granule index, the row of [`PACKING_CSV`] less one). In ParaView,
/// a Glyph filter with sphere glyphs scaled by `radius` (scale factor 2)
/// draws the spheres.
pub fn write_packing_vtu(path: &Path, centres: &[[Real; 3]], radius: Real) -> anyhow::Result<()> {
    let radii = vec![radius; centres.len()];
    let ids: Vec<i64> = (0..centres.len() as i64).collect();
    let cells = Cells::vertices(centres.len());
    let point_data = [
        DataArray {
            name: "radius",
            values: Values::Float64(&radii),
        },
        DataArray {
            name: "id",
            values: Values::Int64(&ids),
        },
    ];
    let grid = UnstructuredGrid {
        points: centres,
        cells: &cells,
        point_data: &point_data,
        cell_data: &[],
    };
    let mut w = create_file(path)?;
    grid.write(&mut w)
        .with_context(|| format!("cannot write to `{}`", path.display()))?;
    finish_file(w, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packing_text_errors_name_the_line() {
        let ok = parse_packing("x_m,y_m,z_m,radius_m\n1,2,3,0.5\r\n-0,5e-4,1e300,1\n").unwrap();
        assert_eq!(ok.len(), 2);
        assert_eq!(ok[1].0[0].to_bits(), (-0.0f64).to_bits());
        let err = |text: &str| format!("{:#}", parse_packing(text).unwrap_err());
        assert!(err("").contains("empty"));
        assert!(err("x,y,z,r\n").contains("line 1: header is `x,y,z,r`"));
        assert!(err("x_m,y_m,z_m,radius_m\n").contains("no granules"));
        let bad = err("x_m,y_m,z_m,radius_m\n1,2,3,0.5\n1,2,abc,0.5\n");
        assert!(bad.contains("line 3: `z_m` = `abc`"), "{bad}");
        assert!(err("x_m,y_m,z_m,radius_m\n1,2,3\n").contains("line 2: no `radius_m`"));
        assert!(err("x_m,y_m,z_m,radius_m\n1,2,3,4,5\n").contains("more than 4"));
        assert!(err("x_m,y_m,z_m,radius_m\n1,2,NaN,1\n").contains("not a finite"));
        assert!(err("x_m,y_m,z_m,radius_m\n1,2,3,0\n").contains("not positive"));
    }
}
