//! A writer of VTK XML unstructured grids (`.vtu`, ASCII), for ParaView and
//! other VTK readers: points, cells of any VTK type, and named point and
//! cell data arrays.
//!
//! Used by `pack` for its `packing.vtu` (a few thousand points, written as
//! text so that a test or a reader can compare the centres digit for digit
//! with `packing.csv`). The bed's snapshots, a million cells and more, are
//! written in binary by the `vtkio` crate instead (`bed::snapshots`, XML
//! feature only: its default features pull in C compression libraries, and
//! its current line is a release candidate, 0.7.0-rc2). This writer came
//! first; moving `pack` onto `vtkio` would leave one writer.
//!
//! Floats are written round-trip exact ([`crate::csv::write_real`]); the
//! file uses `header_type="UInt64"` and 64-bit connectivity and offsets.

use std::io::{self, Write};

use crate::csv::write_real;

/// VTK cell type numbers (`vtkCellType.h`) of the cells used so far.
pub mod cell_type {
    /// A single point.
    pub const VERTEX: u8 = 1;
    /// A two-point segment.
    pub const LINE: u8 = 3;
    /// A three-node triangle.
    pub const TRIANGLE: u8 = 5;
    /// A four-node quadrilateral.
    pub const QUAD: u8 = 9;
    /// A four-node tetrahedron.
    pub const TETRA: u8 = 10;
    /// An eight-node hexahedron.
    pub const HEXAHEDRON: u8 = 12;
}

/// The cells of a grid in VTK's layout: the point indices of every cell one
/// after the other, the end offset of each cell in that list, and each
/// cell's type.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Cells {
    connectivity: Vec<u64>,
    offsets: Vec<u64>,
    types: Vec<u8>,
}

impl Cells {
    /// No cells.
    pub fn new() -> Self {
        Self::default()
    }

    /// One [`cell_type::VERTEX`] per point, for `points` points.
    pub fn vertices(points: usize) -> Self {
        let ids: Vec<u64> = (0..points as u64).collect();
        Self {
            offsets: ids.iter().map(|i| i + 1).collect(),
            connectivity: ids,
            types: vec![cell_type::VERTEX; points],
        }
    }

    /// Appends a cell of type `kind` (see [`cell_type`]) on the point
    /// indices `points`, in VTK's node order for that type.
    pub fn push(&mut self, kind: u8, points: &[u64]) {
        self.connectivity.extend_from_slice(points);
        self.offsets.push(self.connectivity.len() as u64);
        self.types.push(kind);
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.types.len()
    }

    /// True if there are no cells.
    pub fn is_empty(&self) -> bool {
        self.types.is_empty()
    }
}

/// The values of one data array: one per point (or cell).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Values<'a> {
    /// A float scalar (VTK `Float64`).
    Float64(&'a [f64]),
    /// A float 3-vector (VTK `Float64`, 3 components).
    Vector64(&'a [[f64; 3]]),
    /// An integer scalar (VTK `Int64`).
    Int64(&'a [i64]),
}

impl Values<'_> {
    /// Number of tuples.
    pub fn len(&self) -> usize {
        match self {
            Self::Float64(v) => v.len(),
            Self::Vector64(v) => v.len(),
            Self::Int64(v) => v.len(),
        }
    }

    /// True if there are no tuples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A named data array.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DataArray<'a> {
    /// Name shown by the reader (e.g. `radius`).
    pub name: &'a str,
    /// The values.
    pub values: Values<'a>,
}

/// An unstructured grid to write.
#[derive(Clone, Copy, Debug)]
pub struct UnstructuredGrid<'a> {
    /// Point coordinates, m.
    pub points: &'a [[f64; 3]],
    /// The cells on those points.
    pub cells: &'a Cells,
    /// Point data: one value per point in each array.
    pub point_data: &'a [DataArray<'a>],
    /// Cell data: one value per cell in each array.
    pub cell_data: &'a [DataArray<'a>],
}

/// Values per line of a scalar array.
const PER_LINE: usize = 6;

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// Writes `items` `per_line` to a line, each with `item`, indented.
fn write_lines<T>(
    out: &mut dyn Write,
    items: &[T],
    per_line: usize,
    item: impl Fn(&mut dyn Write, &T) -> io::Result<()>,
) -> io::Result<()> {
    for chunk in items.chunks(per_line) {
        out.write_all(b"          ")?;
        for (k, x) in chunk.iter().enumerate() {
            if k > 0 {
                out.write_all(b" ")?;
            }
            item(out, x)?;
        }
        out.write_all(b"\n")?;
    }
    Ok(())
}

fn write_array(out: &mut dyn Write, array: &DataArray<'_>) -> io::Result<()> {
    let name = crate::output::escape_markup(array.name);
    let (kind, components) = match array.values {
        Values::Float64(_) => ("Float64", 1),
        Values::Vector64(_) => ("Float64", 3),
        Values::Int64(_) => ("Int64", 1),
    };
    // Scalars leave NumberOfComponents at its default of 1 (readers such as
    // meshio then give them as flat arrays).
    let components = if components == 1 {
        String::new()
    } else {
        format!(" NumberOfComponents=\"{components}\"")
    };
    writeln!(
        out,
        "        <DataArray type=\"{kind}\" Name=\"{name}\"{components} format=\"ascii\">"
    )?;
    match array.values {
        Values::Float64(v) => write_lines(out, v, PER_LINE, |o, x| write_real(o, *x))?,
        Values::Vector64(v) => write_lines(out, v, 1, |o, p| {
            write_real(o, p[0])?;
            o.write_all(b" ")?;
            write_real(o, p[1])?;
            o.write_all(b" ")?;
            write_real(o, p[2])
        })?,
        Values::Int64(v) => write_lines(out, v, PER_LINE, |o, x| write!(o, "{x}"))?,
    }
    writeln!(out, "        </DataArray>")
}

fn write_integers<T: core::fmt::Display>(
    out: &mut dyn Write,
    kind: &str,
    name: &str,
    values: &[T],
) -> io::Result<()> {
    writeln!(
        out,
        "        <DataArray type=\"{kind}\" Name=\"{name}\" format=\"ascii\">"
    )?;
    write_lines(out, values, PER_LINE, |o, x| write!(o, "{x}"))?;
    writeln!(out, "        </DataArray>")
}

impl UnstructuredGrid<'_> {
    /// Checks that every data array has one value per point (cell) and that
    /// every cell refers to existing points.
    pub fn check(&self) -> io::Result<()> {
        let n = self.points.len();
        for (data, count, what) in [
            (self.point_data, n, "point"),
            (self.cell_data, self.cells.len(), "cell"),
        ] {
            for a in data {
                if a.values.len() != count {
                    return Err(invalid(format!(
                        "VTK {what} data `{}` has {} values for {count} {what}s",
                        a.name,
                        a.values.len()
                    )));
                }
            }
        }
        if let Some(&bad) = self.cells.connectivity.iter().find(|&&i| i >= n as u64) {
            return Err(invalid(format!(
                "VTK cell refers to point {bad} of {n} points"
            )));
        }
        Ok(())
    }

    /// Writes the grid as a VTK XML `UnstructuredGrid` file (one piece,
    /// ASCII) to `out`. Fails with [`io::ErrorKind::InvalidInput`], writing
    /// nothing, if [`UnstructuredGrid::check`] fails.
    pub fn write(&self, out: &mut dyn Write) -> io::Result<()> {
        self.check()?;
        let c = self.cells;
        writeln!(out, "<?xml version=\"1.0\"?>")?;
        writeln!(
            out,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
             header_type=\"UInt64\">"
        )?;
        writeln!(out, "  <UnstructuredGrid>")?;
        writeln!(
            out,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len(),
            c.len()
        )?;
        for (tag, data) in [("PointData", self.point_data), ("CellData", self.cell_data)] {
            writeln!(out, "      <{tag}>")?;
            for a in data {
                write_array(out, a)?;
            }
            writeln!(out, "      </{tag}>")?;
        }
        writeln!(out, "      <Points>")?;
        write_array(
            out,
            &DataArray {
                name: "Points",
                values: Values::Vector64(self.points),
            },
        )?;
        writeln!(out, "      </Points>")?;
        writeln!(out, "      <Cells>")?;
        write_integers(out, "Int64", "connectivity", &c.connectivity)?;
        write_integers(out, "Int64", "offsets", &c.offsets)?;
        write_integers(out, "UInt8", "types", &c.types)?;
        writeln!(out, "      </Cells>")?;
        writeln!(out, "    </Piece>")?;
        writeln!(out, "  </UnstructuredGrid>")?;
        writeln!(out, "</VTKFile>")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The whitespace-separated values of the first `<DataArray … Name="name"`
    /// element of `xml`.
    fn array<'a>(xml: &'a str, name: &str) -> Vec<&'a str> {
        let start = xml
            .find(&format!("Name=\"{name}\""))
            .unwrap_or_else(|| panic!("no array {name}"));
        let body = &xml[start..];
        let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
        body.split_whitespace().collect()
    }

    #[test]
    fn vertices_with_point_data() {
        let points = [[0.0, 1.5e-3, -2.0], [1.0 / 3.0, 0.0, 5e-324]];
        let radius = [0.5e-3, 0.25];
        let ids = [0, 1];
        let cells = Cells::vertices(2);
        let grid = UnstructuredGrid {
            points: &points,
            cells: &cells,
            point_data: &[
                DataArray {
                    name: "radius",
                    values: Values::Float64(&radius),
                },
                DataArray {
                    name: "id",
                    values: Values::Int64(&ids),
                },
            ],
            cell_data: &[],
        };
        let mut buf = Vec::new();
        grid.write(&mut buf).unwrap();
        let xml = String::from_utf8(buf).unwrap();
        assert!(xml.contains("<Piece NumberOfPoints=\"2\" NumberOfCells=\"2\">"));
        let coords: Vec<f64> = array(&xml, "Points")
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(coords, points.concat());
        assert_eq!(array(&xml, "radius"), ["0.0005", "0.25"]);
        assert_eq!(array(&xml, "connectivity"), ["0", "1"]);
        assert_eq!(array(&xml, "offsets"), ["1", "2"]);
        assert_eq!(array(&xml, "types"), ["1", "1"]);
        assert!(xml.ends_with("</VTKFile>\n"));
    }

    #[test]
    fn mixed_cells_and_checks() {
        let mut cells = Cells::new();
        cells.push(cell_type::TRIANGLE, &[0, 1, 2]);
        cells.push(cell_type::LINE, &[2, 0]);
        assert_eq!(cells.offsets, [3, 5]);
        let points = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let area = [0.5];
        let mut grid = UnstructuredGrid {
            points: &points,
            cells: &cells,
            point_data: &[],
            cell_data: &[DataArray {
                name: "a<b",
                values: Values::Float64(&area),
            }],
        };
        let mut buf = Vec::new();
        let err = grid.write(&mut buf).unwrap_err();
        assert!(err.to_string().contains("1 values for 2 cells"), "{err}");
        assert!(buf.is_empty());
        let areas = [0.5, 1.0];
        let data = [DataArray {
            name: "a<b",
            values: Values::Float64(&areas),
        }];
        grid.cell_data = &data;
        grid.write(&mut buf).unwrap();
        let xml = String::from_utf8(buf).unwrap();
        assert!(xml.contains("Name=\"a&lt;b\""));
        assert_eq!(array(&xml, "types"), ["5", "3"]);
        grid.points = &points[..2];
        assert!(grid.check().unwrap_err().to_string().contains("point 2"));
    }
}
