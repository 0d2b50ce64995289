//! A minimal CSV writer for numeric tables: a header row, then rows of
//! integers, floats and short names, comma separated, `\n` line ends, no
//! quoting (column names and text cells must not contain commas, quotes or
//! line breaks).
//!
//! Floats are written round-trip exact: the shortest decimal that parses
//! back to the same `f64` (Rust's `Display`, or `LowerExp` for magnitudes
//! outside [1e-4, 1e15) so tiny and huge values stay short). `-0` keeps its
//! sign; non-finite values are written `NaN`, `inf`, `-inf`.

use std::io::{self, Write};
use std::path::Path;

use anyhow::Context as _;

use crate::output::{create_file, finish_file};

/// One cell of a row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Field {
    /// An integer (counts, indices, 0/1 flags).
    Int(u64),
    /// A float, written round-trip exact.
    Real(f64),
    /// A name (e.g. a granule type), written as is: no commas, quotes or
    /// line breaks.
    Text(&'static str),
}

impl From<u32> for Field {
    fn from(v: u32) -> Self {
        Self::Int(u64::from(v))
    }
}

impl From<bool> for Field {
    fn from(v: bool) -> Self {
        Self::Int(u64::from(v))
    }
}

impl From<f64> for Field {
    fn from(v: f64) -> Self {
        Self::Real(v)
    }
}

/// Writes `x` as the shortest decimal that parses back to the same bits.
pub fn write_real(out: &mut dyn Write, x: f64) -> io::Result<()> {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1.0e-4..1.0e15).contains(&a) {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    }
}

/// A CSV table being written to `W`.
pub struct CsvWriter<W: Write> {
    out: W,
    columns: usize,
    rows: u64,
}

impl<W: Write> CsvWriter<W> {
    /// Starts a table on `out` and writes the `header` row.
    pub fn new(mut out: W, header: &[&str]) -> io::Result<Self> {
        writeln!(out, "{}", header.join(","))?;
        Ok(Self {
            out,
            columns: header.len(),
            rows: 0,
        })
    }

    /// Writes one row. Fails with [`io::ErrorKind::InvalidInput`] (writing
    /// nothing) if `fields` does not have one cell per header column.
    pub fn write_row(&mut self, fields: &[Field]) -> io::Result<()> {
        if fields.len() != self.columns {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "CSV row has {} cells, header has {}",
                    fields.len(),
                    self.columns
                ),
            ));
        }
        for (i, field) in fields.iter().enumerate() {
            if i > 0 {
                self.out.write_all(b",")?;
            }
            match *field {
                Field::Int(v) => write!(self.out, "{v}")?,
                Field::Real(x) => write_real(&mut self.out, x)?,
                Field::Text(t) => self.out.write_all(t.as_bytes())?,
            }
        }
        self.out.write_all(b"\n")?;
        self.rows += 1;
        Ok(())
    }

    /// Data rows written so far (the header not counted).
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Flushes the underlying writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// The underlying writer (not flushed).
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// Writes the file `path`: a header of the names of `columns` (name,
/// meaning: the meanings are for the reader's glossary, not the file),
/// then `rows`. Errors name the file.
pub fn write_table<const N: usize>(
    path: &Path,
    columns: &[(&str, &str); N],
    rows: impl Iterator<Item = [Field; N]>,
) -> anyhow::Result<()> {
    let names = columns.map(|c| c.0);
    let mut csv = CsvWriter::new(create_file(path)?, &names)
        .with_context(|| format!("cannot write to `{}`", path.display()))?;
    for row in rows {
        csv.write_row(&row)
            .with_context(|| format!("cannot write to `{}`", path.display()))?;
    }
    finish_file(csv.into_inner(), path)
}

/// Reads the numeric table `path` that [`write_table`] wrote with
/// `columns`: its header must be their names in order, and every row as
/// many numbers (`NaN` and `inf` included). Errors name the file, and the
/// line of a row that is not numbers.
pub fn read_table<const N: usize>(
    path: &Path,
    columns: &[(&str, &str); N],
) -> anyhow::Result<Vec<[f64; N]>> {
    read_table_or_older(path, columns, N)
}

/// [`read_table`] of a table whose files written by older builds hold
/// only the first `older` of `columns` (the later ones added since): such
/// a file is read too, NaN in the columns it lacks.
pub fn read_table_or_older<const N: usize>(
    path: &Path,
    columns: &[(&str, &str); N],
    older: usize,
) -> anyhow::Result<Vec<[f64; N]>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read `{}`", path.display()))?;
    let mut lines = text.lines();
    let names = columns.map(|c| c.0);
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let held = header.len();
    anyhow::ensure!(
        (held == N || held == older.min(N)) && header == names[..held],
        "`{}`: the header is not {}",
        path.display(),
        names.join(",")
    );
    lines
        .enumerate()
        .map(|(i, line)| {
            let cells: Vec<f64> = line
                .split(',')
                .map(str::parse)
                .collect::<Result<_, _>>()
                .ok()
                .with_context(|| {
                    format!(
                        "`{}` line {}: a cell is not a number",
                        path.display(),
                        i + 2
                    )
                })?;
            anyhow::ensure!(
                cells.len() == held,
                "`{}` line {}: not {held} cells, one per header column",
                path.display(),
                i + 2
            );
            Ok(core::array::from_fn(|c| {
                cells.get(c).copied().unwrap_or(f64::NAN)
            }))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(x: f64) -> String {
        let mut buf = Vec::new();
        write_real(&mut buf, x).unwrap();
        String::from_utf8(buf).unwrap()
    }

    #[test]
    fn reals_round_trip_bit_for_bit() {
        let values = [
            0.0,
            -0.0,
            0.1,
            1.0 / 3.0,
            -2.5e-5,
            1.0e-4,
            123_456.789,
            1.0e15,
            -9.87e300,
            f64::MIN_POSITIVE,
            5.0e-324,
            f64::MAX,
        ];
        for x in values {
            let back: f64 = text(x).parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x:e} written as {}", text(x));
        }
        assert_eq!(text(0.1), "0.1");
        assert_eq!(text(-2.5e-5), "-2.5e-5");
        assert!(text(f64::NAN).parse::<f64>().unwrap().is_nan());
    }

    /// A table written reads back to the same bits; a wrong header, a
    /// short row or a word among the numbers is an error naming the file.
    #[test]
    fn a_table_round_trips_and_a_damaged_one_is_refused() {
        const COLUMNS: [(&str, &str); 2] = [("a", "first"), ("b", "second")];
        let dir = std::env::temp_dir().join(format!("granbed-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        let rows = [[0.1, -2.5e-5], [f64::INFINITY, 3.0]];
        write_table(&path, &COLUMNS, rows.iter().map(|r| r.map(Field::from))).unwrap();
        assert_eq!(read_table(&path, &COLUMNS).unwrap(), rows);
        for (text, says) in [
            ("a,c\n1,2\n", "header"),
            ("a,b\n1,2\n3\n", "line 3: not 2 cells"),
            ("a,b\n1,x\n", "line 2: a cell"),
        ] {
            std::fs::write(&path, text).unwrap();
            let e = format!("{:#}", read_table(&path, &COLUMNS).unwrap_err());
            assert!(e.contains("t.csv") && e.contains(says), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn rows_match_the_header() {
        let mut w = CsvWriter::new(Vec::new(), &["n", "x", "name"]).unwrap();
        w.write_row(&[Field::from(3_u32), Field::from(0.5), Field::Text("B2")])
            .unwrap();
        assert!(w.write_row(&[Field::from(true)]).is_err());
        assert_eq!(w.rows(), 1);
        assert_eq!(
            String::from_utf8(w.into_inner()).unwrap(),
            "n,x,name\n3,0.5,B2\n"
        );
    }
}
