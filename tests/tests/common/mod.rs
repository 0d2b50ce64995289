//! Helpers shared by the CLI suites: running the command line in-process,
//! reading its CSV output, and one tolerance check.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::Path;

/// A fresh (emptied, not created) output directory `<suite>-<name>` under
/// Cargo's per-target temporary directory.
pub fn fresh_dir(suite: &str, name: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{suite}-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// What a run of the CLI produced.
pub struct Run {
    /// Exit status the binary would return.
    pub code: u8,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

/// Runs `granbed-cli ARGS` in-process: exactly the two calls the binary's
/// `main` makes (`granbed_cli::run`, then `granbed_cli::error::report` on
/// failure), with in-memory streams. The binary itself cannot be spawned
/// from this package: Cargo sets `CARGO_BIN_EXE_granbed-cli` only for the
/// CLI package's own integration tests.
pub fn cli(args: &[&str]) -> Run {
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let argv = core::iter::once("granbed-cli").chain(args.iter().copied());
    let code = match granbed_cli::run(argv, &mut out, &mut err) {
        Ok(()) => 0,
        Err(e) => granbed_cli::error::report(&e, &mut err),
    };
    Run {
        code,
        stdout: String::from_utf8(out).expect("stdout is UTF-8"),
        stderr: String::from_utf8(err).expect("stderr is UTF-8"),
    }
}

/// Writes to `path` the published scene (`bed --print-scene`) with
/// `line` added to its `[material]` table, e.g. a yield stress that every
/// type of a `--types` run would share.
pub fn write_scene_with_material(path: &Path, line: &str) {
    let printed = cli(&["bed", "--print-scene"]);
    assert_eq!(printed.code, 0, "{}", printed.stderr);
    let text = printed
        .stdout
        .replace("[material]\n", &format!("[material]\n{line}\n"));
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// A parsed CSV table (numbers or text cells).
pub struct Table {
    columns: HashMap<String, usize>,
    /// The header line.
    pub header: String,
    /// The cells, row by row.
    pub cells: Vec<Vec<String>>,
}

impl Table {
    /// Parses CSV text with a header row; every row has the header's width.
    pub fn parse(text: &str) -> Self {
        let mut lines = text.lines();
        let header = lines.next().expect("CSV has a header").to_owned();
        let columns = header
            .split(',')
            .enumerate()
            .map(|(i, name)| (name.to_owned(), i))
            .collect::<HashMap<_, _>>();
        let cells: Vec<Vec<String>> = lines
            .map(|line| {
                let row: Vec<String> = line.split(',').map(str::to_owned).collect();
                assert_eq!(row.len(), columns.len(), "row {line:?}");
                row
            })
            .collect();
        Self {
            columns,
            header,
            cells,
        }
    }

    /// Reads and parses the CSV file at `path`.
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        Self::parse(&text)
    }

    /// Index of column `name`.
    pub fn col(&self, name: &str) -> usize {
        *self
            .columns
            .get(name)
            .unwrap_or_else(|| panic!("no column {name}"))
    }

    /// Every row as numbers (panics on a non-numeric cell).
    pub fn rows(&self) -> Vec<Vec<f64>> {
        self.cells
            .iter()
            .map(|row| {
                row.iter()
                    .map(|cell| cell.parse().unwrap_or_else(|_| panic!("bad cell {cell:?}")))
                    .collect()
            })
            .collect()
    }

    /// Column `name` as numbers.
    pub fn num(&self, name: &str) -> Vec<f64> {
        let c = self.col(name);
        self.cells
            .iter()
            .map(|row| {
                row[c]
                    .parse()
                    .unwrap_or_else(|_| panic!("bad cell {:?} in {name}", row[c]))
            })
            .collect()
    }

    /// Column `name` as text.
    pub fn text(&self, name: &str) -> Vec<&str> {
        let c = self.col(name);
        self.cells.iter().map(|row| row[c].as_str()).collect()
    }
}

/// The `granbed-cli bed` flags of a CI-sized bed: `granules` coarse (4x1,
/// 160-hex) granules poured into a 5 mm die and pressed to `strain`.
#[allow(dead_code)]
pub const fn small_bed<'a>(granules: &'a str, strain: &'a str) -> [&'a str; 8] {
    [
        "--granules",
        granules,
        "--mesh",
        "4x1",
        "--die-diameter-mm",
        "5",
        "--strain",
        strain,
    ]
}

/// The stability suite's test size: `granules` coarse granules in a 4.2 mm
/// die, pressed to 30 % (8 lie in one layer, so every contact is a wall
/// contact: the bed that broke selective ×30).
pub const fn die_4_2mm(granules: &str) -> [&str; 8] {
    [
        "--granules",
        granules,
        "--mesh",
        "4x1",
        "--die-diameter-mm",
        "4.2",
        "--strain",
        "0.3",
    ]
}

/// Asserts |actual − expected| ≤ abs + rel·|expected|, naming the quantity.
#[track_caller]
pub fn assert_close(what: &str, actual: f64, expected: f64, rel: f64, abs: f64) {
    let err = (actual - expected).abs();
    let tol = abs + rel * expected.abs();
    assert!(
        err <= tol,
        "{what}: got {actual:.16e}, expected {expected:.16e} (|err| = {err:.3e} > tol = {tol:.3e})"
    );
}

/// The parsed `summary.json` in `dir`.
pub fn summary(dir: &Path) -> serde_json::Value {
    let path = dir.join("summary.json");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// Field `key` of a summary as a number (panics if missing or null).
pub fn number(summary: &serde_json::Value, key: &str) -> f64 {
    summary[key]
        .as_f64()
        .unwrap_or_else(|| panic!("summary field {key} is {:?}", summary[key]))
}

/// One XML element: name, attributes and the text directly inside it.
pub struct Element {
    /// Tag name.
    pub name: String,
    /// Attributes.
    pub attrs: HashMap<String, String>,
    /// Text directly inside.
    pub text: String,
}

/// A minimal XML reader, enough for the VTU files: skips the `<?xml ?>`
/// declaration, checks that every tag is closed in order, and returns the
/// elements in the order they close.
pub fn parse_xml(xml: &str) -> Vec<Element> {
    let mut open: Vec<Element> = Vec::new();
    let mut done = Vec::new();
    let mut rest = xml;
    while let Some(lt) = rest.find('<') {
        if let Some(top) = open.last_mut() {
            top.text.push_str(&rest[..lt]);
        } else {
            assert!(rest[..lt].trim().is_empty(), "text outside the root");
        }
        let gt = rest[lt..].find('>').expect("unclosed tag") + lt;
        let tag = &rest[lt + 1..gt];
        rest = &rest[gt + 1..];
        if tag.starts_with('?') {
            assert!(tag.ends_with('?'), "bad declaration <{tag}>");
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            let e = open
                .pop()
                .unwrap_or_else(|| panic!("</{name}> closes nothing"));
            assert_eq!(e.name, name, "<{}> closed by </{name}>", e.name);
            done.push(e);
            continue;
        }
        let empty = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let (name, mut attrs_text) = tag.split_once(' ').unwrap_or((tag, ""));
        let mut attrs = HashMap::new();
        while let Some((key, value)) = attrs_text.split_once("=\"") {
            let (value, after) = value.split_once('"').expect("unterminated attribute");
            attrs.insert(key.trim().to_owned(), value.to_owned());
            attrs_text = after;
        }
        assert!(attrs_text.trim().is_empty(), "bad attributes in <{tag}>");
        let e = Element {
            name: name.to_owned(),
            attrs,
            text: String::new(),
        };
        if empty {
            done.push(e);
        } else {
            open.push(e);
        }
    }
    assert!(rest.trim().is_empty(), "text after the root");
    assert!(open.is_empty(), "unclosed <{}>", open[0].name);
    done
}

/// Standard base64 (with padding), for the binary VTK data arrays.
pub fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("bad base64 character {c:?}"),
        }
    };
    let bytes: Vec<u8> = text.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    assert_eq!(bytes.len() % 4, 0, "base64 length");
    let mut out = Vec::new();
    for chunk in bytes.chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let n = chunk
            .iter()
            .map(|&c| if c == b'=' { 0 } else { value(c) })
            .fold(0u32, |n, v| (n << 6) | v);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// The values of a binary (inline base64, UInt64 header) little-endian
/// `DataArray` of 8-byte numbers, as `f64` (Float64) or `i64` (Int64).
pub fn binary_values(e: &Element) -> Vec<f64> {
    assert_eq!(e.attrs["format"], "binary", "{}", e.attrs["Name"]);
    let bytes = base64_decode(&e.text);
    let (header, data) = bytes.split_at(8);
    let len = u64::from_le_bytes(header.try_into().unwrap()) as usize;
    assert_eq!(len, data.len(), "header of {}", e.attrs["Name"]);
    data.chunks(8)
        .map(|b| {
            let b: [u8; 8] = b.try_into().unwrap();
            match e.attrs["type"].as_str() {
                "Float64" => f64::from_le_bytes(b),
                "Int64" => i64::from_le_bytes(b) as f64,
                t => panic!("unexpected type {t}"),
            }
        })
        .collect()
}

/// What a VTU snapshot holds, as the tests read it.
pub struct Snapshot {
    /// NumberOfPoints.
    pub points: usize,
    /// NumberOfCells.
    pub cells: usize,
    /// The cell data arrays asked for, by name.
    pub cell_data: HashMap<String, Vec<f64>>,
    /// The cell types.
    pub types: Vec<u8>,
}

/// Reads a binary VTU file of `granbed-cli bed` with its cell data arrays
/// `arrays` (each must be there).
pub fn read_vtu(path: &Path, arrays: &[&str]) -> Snapshot {
    let xml = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let elements = parse_xml(&xml);
    let root = elements.last().unwrap();
    assert_eq!(root.name, "VTKFile");
    assert_eq!(root.attrs["type"], "UnstructuredGrid");
    let piece = elements.iter().find(|e| e.name == "Piece").unwrap();
    let count = |k: &str| piece.attrs[k].parse::<usize>().unwrap();
    let array = |name: &str| {
        elements
            .iter()
            .find(|e| {
                e.name == "DataArray" && e.attrs.get("Name").map(String::as_str) == Some(name)
            })
            .unwrap_or_else(|| panic!("no DataArray {name} in {}", path.display()))
    };
    let types = base64_decode(&array("types").text)[8..].to_vec();
    let cell_data = arrays
        .iter()
        .map(|&n| (n.to_string(), binary_values(array(n))))
        .collect();
    Snapshot {
        points: count("NumberOfPoints"),
        cells: count("NumberOfCells"),
        cell_data,
        types,
    }
}

/// A checkpoint file (`checkpoint.bin`) of `payload` labelled `version`:
/// the magic of `file` (its first 16 bytes), the version, the payload's
/// length and its FNV-1a 64 checksum, then the payload, as
/// `bed::checkpoint` writes them. The tests make older formats and
/// damaged files with it.
pub fn checkpoint_file(file: &[u8], version: u32, payload: &[u8]) -> Vec<u8> {
    let checksum = payload.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    let mut out = file[..16].to_vec();
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&checksum.to_le_bytes());
    out.extend_from_slice(payload);
    out
}

/// The format version of the checkpoint file `file`.
pub fn checkpoint_version(file: &[u8]) -> u32 {
    u32::from_le_bytes(file[16..20].try_into().expect("a checkpoint header"))
}
