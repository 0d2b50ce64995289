//! `granbed-cli export-mesh`: the granule reference mesh (full sphere or
//! octant) in CalculiX/Abaqus `.inp` form, so peers compute on exactly
//! granbed's mesh.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context as _;
use clap::{Args, ValueEnum};

use crate::model::{MeshLevel, OwnedReference};
use crate::output::{Output, Streams};

/// Length unit of the exported coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LengthUnit {
    /// Metres.
    M,
    /// Millimetres (with stresses in MPa = N/mm², a consistent unit set).
    Mm,
}

/// Export the granule mesh for another finite-element code.
#[derive(Args, Debug)]
pub struct ExportMeshArgs {
    /// Mesh level NxM: n core divisions (even), m shell layers; 8x2 is the
    /// standard 1280-hex granule, 4x1 the coarse 160-hex one.
    #[arg(long, default_value = "8x2")]
    pub mesh: MeshLevel,
    /// Export only the positive octant (x, y, z ≥ 0), with node sets XSYM,
    /// YSYM, ZSYM on the symmetry planes.
    #[arg(long)]
    pub octant: bool,
    /// Granule diameter, mm (0.001 ≤ d ≤ 1000).
    #[arg(value_parser = crate::numbers::real, long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub diameter_mm: f64,
    /// Length unit of the node coordinates.
    #[arg(long, value_enum, default_value = "m")]
    pub length_unit: LengthUnit,
    /// Output `.inp` file; `-` or absent writes to stdout.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// CalculiX/Abaqus C3D8 face label of the hex face holding the node slots
/// `slots` (granbed's hex8 node order is the C3D8 order).
fn c3d8_face(slots: [usize; 4]) -> Option<&'static str> {
    let mut s = slots;
    s.sort_unstable();
    Some(match s {
        [0, 1, 2, 3] => "S1",
        [4, 5, 6, 7] => "S2",
        [0, 1, 4, 5] => "S3",
        [1, 2, 5, 6] => "S4",
        [2, 3, 6, 7] => "S5",
        [0, 3, 4, 7] => "S6",
        _ => return None,
    })
}

impl ExportMeshArgs {
    /// Runs the export.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        let radius = crate::granule::radius_of_diameter_mm(self.diameter_mm)?;
        let mesh = OwnedReference::sphere(radius, self.mesh, self.octant)?;
        let scale = match self.length_unit {
            LengthUnit::M => 1.0,
            LengthUnit::Mm => 1.0e3,
        };
        let mut out = Output::open(self.out.as_deref(), &mut *streams.stdout)?;
        write_inp(&mut out, &mesh, scale, self).context("writing the .inp file")?;
        out.finish()?;
        drop(out);
        writeln!(
            streams.stderr,
            "export-mesh: {} {}: {} nodes, {} hexes, {} surface faces",
            self.mesh,
            if self.octant { "octant" } else { "sphere" },
            mesh.positions.len(),
            mesh.hexes.len(),
            mesh.quads.len()
        )?;
        Ok(())
    }
}

fn write_inp(
    w: &mut dyn Write,
    mesh: &OwnedReference,
    scale: f64,
    args: &ExportMeshArgs,
) -> std::io::Result<()> {
    let unit = match args.length_unit {
        LengthUnit::M => "m",
        LengthUnit::Mm => "mm",
    };
    let part = if args.octant {
        "positive octant"
    } else {
        "full sphere"
    };
    writeln!(
        w,
        "** granbed granule mesh {} ({part}), diameter {} mm, coordinates in {unit}",
        args.mesh, args.diameter_mm
    )?;
    writeln!(
        w,
        "** regenerate: granbed-cli export-mesh --mesh {}{} --length-unit {unit}",
        args.mesh,
        if args.octant { " --octant" } else { "" },
    )?;
    writeln!(w, "*NODE, NSET=NALL")?;
    for (i, x) in mesh.positions.iter().enumerate() {
        // 13 significant digits: every field fits CalculiX's 20-character limit.
        let [a, b, c] = x.map(|v| v * scale);
        writeln!(w, "{}, {a:.12e}, {b:.12e}, {c:.12e}", i + 1)?;
    }
    writeln!(w, "*ELEMENT, TYPE=C3D8, ELSET=EALL")?;
    for (e, h) in mesh.hexes.iter().enumerate() {
        let ids: Vec<String> = h.iter().map(|id| (id + 1).to_string()).collect();
        writeln!(w, "{}, {}", e + 1, ids.join(", "))?;
    }
    let first_surface = mesh.surface_range().start;
    let mut sets: Vec<(&str, Vec<usize>)> =
        vec![("SURFNODES", (first_surface..mesh.positions.len()).collect())];
    if args.octant {
        for (a, name) in ["XSYM", "YSYM", "ZSYM"].into_iter().enumerate() {
            sets.push((
                name,
                (0..mesh.positions.len())
                    .filter(|&i| mesh.positions[i][a] == 0.0)
                    .collect(),
            ));
        }
    }
    for (name, ids) in sets {
        writeln!(w, "*NSET, NSET={name}")?;
        for chunk in ids.chunks(10) {
            let line: Vec<String> = chunk.iter().map(|id| (id + 1).to_string()).collect();
            writeln!(w, "{}", line.join(", "))?;
        }
    }
    // The outer surface as element faces (each quad is a face of one hex).
    writeln!(w, "*SURFACE, NAME=OUTER, TYPE=ELEMENT")?;
    for q in &mesh.quads {
        let found = mesh.hexes.iter().enumerate().find_map(|(e, h)| {
            let slots: Option<Vec<usize>> =
                q.iter().map(|id| h.iter().position(|x| x == id)).collect();
            let slots: [usize; 4] = slots?.try_into().ok()?;
            c3d8_face(slots).map(|f| (e, f))
        });
        if let Some((e, face)) = found {
            writeln!(w, "{}, {}", e + 1, face)?;
        }
    }
    Ok(())
}
