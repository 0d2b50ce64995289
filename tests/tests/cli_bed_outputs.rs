//! The viewing outputs of `granbed-cli bed` on a tiny bed (20 coarse 4x1
//! granules in a 5 mm die, to 12 % strain, snapshots at 0, 5 and 10 %):
//! the VTU snapshots and their `.pvd` collection parse as XML, have one
//! cell per surface quad (or hex) of every granule and the per-granule cell
//! data, and read back in meshio (Python; skipped with a notice only when
//! python3 or meshio is missing outside CI); the SVG plots exist; the
//! report holds the summary values and the scene.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{cli, number, parse_xml, read_vtu, summary};
use granbed_cli::bed::DEFAULT_SCENE;
use granbed_cli::model::{MeshLevel, OwnedReference};

fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_bed_outputs", name)
}

const GRANULES: usize = 20;
/// The scene's snapshot strains in order, then the final state's (the
/// tiny bed's `--strain 0.12`, which the list does not reach).
const SNAPSHOTS: [f64; 4] = [0.0, 0.05, 0.1, 0.12];
/// The cell data holding one value per granule.
const GRANULE_ARRAYS: [&str; 4] = ["granule", "relative_density", "heywood_dv", "heywood_d"];
/// The cell data holding the value of each cell's element (a quad's: the
/// hex under it).
const ELEMENT_ARRAYS: [&str; 4] = [
    "pressure_pa",
    "von_mises_pa",
    "axial_stress_pa",
    "element_relative_density",
];
/// Every cell data array of a snapshot.
const CELL_ARRAYS: [&str; 8] = [
    GRANULE_ARRAYS[0],
    GRANULE_ARRAYS[1],
    GRANULE_ARRAYS[2],
    GRANULE_ARRAYS[3],
    ELEMENT_ARRAYS[0],
    ELEMENT_ARRAYS[1],
    ELEMENT_ARRAYS[2],
    ELEMENT_ARRAYS[3],
];

/// Runs the tiny bed into `dir` with `extra` flags; the scene file (the
/// published scene with three snapshot strains) is written beside `dir`.
fn tiny_bed(dir: &Path, strain: &str, extra: &[&str]) {
    let scene = dir.with_extension("toml");
    std::fs::write(
        &scene,
        DEFAULT_SCENE.replace(
            "snapshot_strains = [0.0, 0.1, 0.2, 0.3]",
            "snapshot_strains = [0.1, 0.0, 0.05]",
        ),
    )
    .unwrap();
    let mut argv = vec![
        "bed",
        "--quiet",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ];
    argv.extend_from_slice(&common::small_bed("20", strain));
    argv.extend_from_slice(extra);
    let run = cli(&argv);
    assert_eq!(run.code, 0, "bed failed:\n{}", run.stderr);
}

/// The coarse granule mesh of the tiny bed.
fn mesh() -> OwnedReference {
    OwnedReference::sphere(0.5e-3, "4x1".parse::<MeshLevel>().unwrap(), false).unwrap()
}

/// The `(timestep, file)` entries of a `.pvd` collection.
fn read_pvd(path: &Path) -> Vec<(f64, String)> {
    let xml = std::fs::read_to_string(path).unwrap();
    let elements = parse_xml(&xml);
    assert_eq!(elements.last().unwrap().attrs["type"], "Collection");
    elements
        .iter()
        .filter(|e| e.name == "DataSet")
        .map(|e| {
            (
                e.attrs["timestep"].parse().unwrap(),
                e.attrs["file"].clone(),
            )
        })
        .collect()
}

/// The per-file summary meshio gives of `files`: one line per file,
/// `cells <type> <n> <array>=<min>,<max> ...`; `None` (with a notice) when
/// python3 or meshio is missing outside CI. In CI (`CI` set) they must be
/// there: `.ci/setup` installs meshio.
fn meshio_summary(files: &[PathBuf]) -> Option<Vec<String>> {
    const SCRIPT: &str = r#"
import sys
import meshio
for path in sys.argv[1:]:
    m = meshio.read(path)
    parts = []
    for block in m.cells:
        parts.append("cells %s %d" % (block.type, len(block.data)))
    for name in sorted(m.cell_data):
        v = m.cell_data[name][0]
        parts.append("%s=%r,%r" % (name, float(v.min()), float(v.max())))
    parts.append("points %d" % len(m.points))
    print(" ".join(parts))
"#;
    let has_meshio = Command::new("python3")
        .args(["-c", "import meshio"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_meshio {
        assert!(
            std::env::var_os("CI").is_none(),
            "python3 with meshio is missing in CI (.ci/setup installs it)"
        );
        eprintln!("NOTICE: python3 or meshio missing: the meshio read-back is skipped");
        return None;
    }
    let out = Command::new("python3")
        .arg("-c")
        .arg(SCRIPT)
        .args(files)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "meshio failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(str::to_owned)
            .collect(),
    )
}

#[test]
fn snapshots_plots_and_report() {
    let dir = out_dir("surfaces");
    tiny_bed(&dir, "0.12", &[]);
    let mesh = mesh();
    let quads = mesh.quads.len();
    assert_eq!(quads, 96);

    // The collection lists the three snapshots in strain order, then the
    // final state.
    let pvd = read_pvd(&dir.join("vtk/bed.pvd"));
    let files: Vec<String> = (0..4).map(|k| format!("bed_{k}.vtu")).collect();
    assert_eq!(
        pvd,
        SNAPSHOTS
            .iter()
            .copied()
            .zip(files.iter().cloned())
            .collect::<Vec<_>>()
    );

    // Beside each snapshot its section picture: hexes cut by y = 0, all
    // of the darkest colour before any load, several colours at the end;
    // report.html shows them in strain order.
    let report = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let mut at = 0;
    for k in 0..files.len() {
        let name = format!("vtk/section_{k}.svg");
        let svg = std::fs::read_to_string(dir.join(&name)).unwrap();
        parse_xml(&svg);
        let fills: std::collections::BTreeSet<&str> = svg
            .lines()
            .filter(|l| l.starts_with("<polygon"))
            .filter_map(|l| l.split("fill=\"").nth(1)?.split('"').next())
            .collect();
        assert!(!fills.is_empty(), "{name}: no hex cut");
        if k == 0 {
            assert_eq!(fills.into_iter().collect::<Vec<_>>(), ["#440154"], "{name}");
        } else if k + 1 == files.len() {
            assert!(fills.len() > 5, "{name}: {fills:?}");
        }
        let img = format!("<img src=\"{name}\"");
        let found = report[at..]
            .find(&img)
            .unwrap_or_else(|| panic!("report lacks {img}"));
        at += found + img.len();
        // The picture's caption links its snapshot's tables; the snapshot
        // at C = 0, before the first step, has none.
        let caption = &report[at..at + report[at..].find("</figcaption>").unwrap()];
        for table in [
            format!("vtk/contacts_{k}.csv"),
            format!("vtk/granules_{k}.csv"),
        ] {
            assert_eq!(dir.join(&table).is_file(), k > 0, "{table}");
            assert_eq!(
                caption.contains(&format!("<a href=\"{table}\">")),
                k > 0,
                "{caption}"
            );
        }
    }

    let mut mean_density = Vec::new();
    let mut max_axial = Vec::new();
    for file in &files {
        let s = read_vtu(&dir.join("vtk").join(file), &CELL_ARRAYS);
        assert_eq!(s.cells, GRANULES * quads, "{file}");
        assert_eq!(s.points, GRANULES * mesh.surface_nodes, "{file}");
        assert!(s.types.len() == s.cells && s.types.iter().all(|&t| t == 9));
        let ids = &s.cell_data["granule"];
        assert_eq!(ids.len(), s.cells);
        for (g, chunk) in ids.chunks(quads).enumerate() {
            assert!(chunk.iter().all(|&i| i == g as f64), "{file}: ids");
        }
        for name in CELL_ARRAYS {
            let v = &s.cell_data[name];
            assert_eq!(v.len(), s.cells, "{file}: {name}");
            assert!(v.iter().all(|x| x.is_finite()), "{file}: {name}");
        }
        for name in GRANULE_ARRAYS {
            // One value per granule.
            let v = &s.cell_data[name];
            assert!(v.chunks(quads).all(|c| c.iter().all(|x| *x == c[0])));
        }
        let axial = &s.cell_data["axial_stress_pa"];
        max_axial.push(axial.iter().copied().fold(f64::NEG_INFINITY, f64::max));
        // The von Mises stress is a norm; at the start (every granule a
        // rigid body, untouched) there is no stress and no densification.
        assert!(s.cell_data["von_mises_pa"].iter().all(|&q| q >= 0.0));
        if file == &files[0] {
            for name in ["pressure_pa", "von_mises_pa", "axial_stress_pa"] {
                let v = &s.cell_data[name];
                assert!(v.iter().all(|x| x.abs() < 1e-3), "{file}: {name}");
            }
            let rho = &s.cell_data["element_relative_density"];
            assert!(rho.iter().all(|x| (x - 0.8).abs() < 1e-9), "{file}");
        }
        let rho = &s.cell_data["relative_density"];
        mean_density.push(rho.iter().sum::<f64>() / rho.len() as f64);
        let a = &s.cell_data["heywood_dv"];
        assert!(a.iter().all(|&x| (5.9..7.5).contains(&x)), "{file}: α_SV");
    }
    // Undeformed granules hold η0 = 0.8; pressed, they densify.
    assert!((mean_density[0] - 0.8).abs() < 1e-9, "{mean_density:?}");
    assert!(mean_density[2] > mean_density[0], "{mean_density:?}");
    assert!(mean_density[3] > mean_density[2], "{mean_density:?}");
    // Pressed, some element carries an axial compression of kPa.
    assert!(max_axial[3] > 1e3, "largest axial stress {max_axial:?}");

    // meshio reads the same cells and arrays.
    let paths: Vec<PathBuf> = files.iter().map(|f| dir.join("vtk").join(f)).collect();
    if let Some(lines) = meshio_summary(&paths) {
        assert_eq!(lines.len(), 4);
        for line in &lines {
            assert!(
                line.starts_with(&format!("cells quad {}", GRANULES * quads)),
                "{line}"
            );
            for name in CELL_ARRAYS {
                assert!(line.contains(&format!(" {name}=")), "{line}");
            }
            assert!(
                line.contains(&format!("granule=0.0,{}.0", GRANULES - 1)),
                "{line}"
            );
            assert!(
                line.ends_with(&format!("points {}", GRANULES * mesh.surface_nodes)),
                "{line}"
            );
        }
    }

    // The plots.
    for name in [
        "pressure_strain.svg",
        "kawakita.svg",
        "heckel.svg",
        "coordination_strain.svg",
        "relative_density_strain.svg",
        "heywood_strain.svg",
        "solid_fraction_pressure.svg",
        "coordination_density.svg",
        "energy_strain.svg",
        "density_height.svg",
        "die_wall_strain.svg",
        "stress_height.svg",
        "density_map.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join("plots").join(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(svg.contains("<svg"), "{name}");
        assert!(svg.contains("</svg>"), "{name}");
    }

    // The report: the summary's values (as written in summary.json, in
    // the cell's title; the cell shows them to four digits), the plots
    // inline and the scene.
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.trim_end().ends_with("</html>"));
    assert_eq!(html.matches("<svg").count(), 13);
    let s = summary(&dir);
    // The final solid fraction is the last row's, and the material every
    // parameter of the type (B2: E 1 MPa, true density 1500 kg/m³).
    let rows = common::Table::read(&dir.join("compression.csv"));
    assert_eq!(
        s["final_solid_fraction"].as_f64().unwrap(),
        *rows.num("bed_solid_fraction").last().unwrap()
    );
    assert_eq!(s["material"]["youngs_modulus_pa"], 1e6);
    assert_eq!(s["material"]["true_density_kg_m3"], 1500.0);
    assert_eq!(s["material"]["eta0"], s["eta0"]);
    // The granules' packing fraction is their envelope volume over the die
    // volume: every granule holds the same solid η0 V0, so from the final
    // snapshot's granule table it is D × the mean of 1/η over the
    // granules. They start near η0 = 0.8, so it lies well above D. The key
    // results name the strains the certificate judged: the second half of
    // the rows.
    let (phi, d_end) = (
        number(&s, "final_packing_fraction"),
        number(&s, "final_solid_fraction"),
    );
    let granules =
        common::Table::read(&dir.join(format!("vtk/granules_{}.csv", SNAPSHOTS.len() - 1)));
    let eta = granules.num("relative_density");
    let from_table = d_end * eta.iter().map(|e| 1.0 / e).sum::<f64>() / eta.len() as f64;
    assert!(
        (phi - from_table).abs() < 1e-9 * phi,
        "{phi} against {from_table} from the granules' table"
    );
    assert!(phi > 1.2 * d_end && phi < 1.0, "{phi}");
    let strains = rows.num("strain");
    let judged = &strains[strains.len() / 2..];
    let window = s["quasi_static_strains"].as_array().unwrap();
    assert_eq!(window[0].as_f64().unwrap(), judged[0]);
    assert_eq!(window[1].as_f64().unwrap(), *judged.last().unwrap());
    assert!(
        html.contains("quasi-static certificate (its kinetic and force figures judged over C = "),
        "no window"
    );
    // The key results first, each plot captioned.
    let key = html.find("<h2>Key results</h2>").expect("no key results");
    assert!(key < html.find("<h2>Plots</h2>").unwrap());
    assert!(html.contains("solid fraction D: poured (D0) → at the end, in the die"));
    assert_eq!(html.matches("<p class=\"caption\">").count(), 13);
    // The Kawakita fit over each window, the Heckel fit on the mean punch
    // pressure over the Heckel rows, and a glossary row for every column
    // of compression.csv, in its order.
    let windows = s["kawakita_windows"].as_array().unwrap();
    let starts: Vec<f64> = windows
        .iter()
        .map(|k| k["min_strain"].as_f64().unwrap())
        .collect();
    assert_eq!(starts, [0.10, 0.15, 0.20, 0.25]);
    assert!(html.contains("<h3>The fits by window</h3>"));
    assert_eq!(s["heckel_mean_pressure"]["points"], s["heckel"]["points"]);
    let glossary = &html[html.find("<h3>compression.csv</h3>").unwrap()..];
    let mut at = 0;
    for column in rows.header.split(',') {
        let cell = format!("<tr><td class=\"value\">{column}</td>");
        let found = glossary[at..]
            .find(&cell)
            .unwrap_or_else(|| panic!("glossary lacks {column}"));
        at += found + cell.len();
    }
    for key in [
        "final_strain",
        "max_pressure_pa",
        "initial_bed_height_m",
        "granules",
        "elements",
        "steps",
        "element_steps",
        "min_jacobian",
        "energy_residual_rel",
    ] {
        let value = s[key].to_string();
        let shown = match s[key].as_u64() {
            Some(count) => count.to_string(),
            None => granbed_cli::numbers::significant(s[key].as_f64().unwrap(), 4),
        };
        assert!(
            html.contains(&format!(
                "<td class=\"value\" title=\"{value}\">{shown}</td>"
            )),
            "report lacks {key} = {value} shown as {shown}"
        );
    }
    assert!(html.contains(&format!(
        "<td>version</td><td class=\"value\" title=\"{0}\">{0}</td>",
        s["version"].as_str().unwrap()
    )));
    // Named and versioned as the granule's and the pour's summaries are.
    assert_eq!(s["format"], "granbed-bed-summary");
    assert_eq!(s["format_version"], 1);
    for line in [
        "granules = 20",
        "mesh = &quot;4x1&quot;",
        "final_strain = 0.12",
    ] {
        assert!(html.contains(line), "report lacks the scene line {line}");
    }
    assert!(html.contains("snapshot_strains = ["), "no snapshot strains");
    // Every warning of the summary is listed above the table, escaped,
    // and not again as a raw JSON list in it.
    let warnings = s["warnings"].as_array().unwrap();
    assert!(
        !warnings.is_empty(),
        "the tiny bed has warnings (its Kawakita fit, its certificate)"
    );
    let (head, table) = html.split_at(html.find("<h2>Summary</h2>").unwrap());
    assert!(head.contains("<h2>Warnings</h2>"));
    for w in warnings {
        let escaped = granbed_cli::html::html_escape(w.as_str().unwrap());
        assert!(head.contains(&format!("<li>{escaped}</li>")), "{escaped}");
    }
    assert!(!table.contains("<td>warnings</td>"));
    assert!(table.contains("<td>quasi_static.passed</td>"));
}

#[test]
fn full_mesh_snapshots_hold_every_hex() {
    let dir = out_dir("hexes");
    tiny_bed(&dir, "0.01", &["--vtk-full-mesh"]);
    let mesh = mesh();
    // Only the snapshot at C = 0 is reached, then the final state.
    assert_eq!(
        read_pvd(&dir.join("vtk/bed.pvd")),
        [
            (0.0, "bed_0.vtu".to_string()),
            (0.01, "bed_1.vtu".to_string())
        ]
    );
    let s = read_vtu(&dir.join("vtk/bed_0.vtu"), &CELL_ARRAYS);
    assert_eq!(s.cells, GRANULES * mesh.hexes.len());
    assert_eq!(s.points, GRANULES * mesh.positions.len());
    assert!(s.types.iter().all(|&t| t == 12));
    let rho = &s.cell_data["relative_density"];
    assert!(rho.iter().all(|x| (x - 0.8).abs() < 1e-9));
    let path = dir.join("vtk/bed_0.vtu");
    if let Some(lines) = meshio_summary(&[path]) {
        assert!(
            lines[0].starts_with(&format!("cells hexahedron {}", GRANULES * mesh.hexes.len())),
            "{}",
            lines[0]
        );
    }
}

/// A surface quad shows the element values of the hex under it: the
/// final snapshot of the tiny bed written as surfaces and as hexes (the
/// same run, deterministic) agree quad by quad with the hex holding the
/// quad's four nodes.
#[test]
fn a_surface_quad_shows_the_element_under_it() {
    let (surfaces, hexes) = (out_dir("quads"), out_dir("quads-hexes"));
    tiny_bed(&surfaces, "0.12", &[]);
    tiny_bed(&hexes, "0.12", &["--vtk-full-mesh"]);
    let mesh = mesh();
    let last = |dir: &Path| read_vtu(&dir.join("vtk/bed_3.vtu"), &ELEMENT_ARRAYS);
    let (s, h) = (last(&surfaces), last(&hexes));
    let (quads, elements) = (mesh.quads.len(), mesh.hexes.len());
    let hex_of: Vec<usize> = mesh
        .quads
        .iter()
        .map(|q| {
            let holding: Vec<usize> = (0..elements)
                .filter(|&e| q.iter().all(|n| mesh.hexes[e].contains(n)))
                .collect();
            assert_eq!(holding.len(), 1, "quad {q:?} on hexes {holding:?}");
            holding[0]
        })
        .collect();
    for name in ELEMENT_ARRAYS {
        let (sv, hv) = (&s.cell_data[name], &h.cell_data[name]);
        let mut compressed = 0;
        for g in 0..GRANULES {
            for (q, &e) in hex_of.iter().enumerate() {
                let (a, b) = (sv[g * quads + q], hv[g * elements + e]);
                assert_eq!(a.to_bits(), b.to_bits(), "{name}: granule {g} quad {q}");
                compressed += usize::from(name == "pressure_pa" && a > 0.0);
            }
        }
        assert!(
            name != "pressure_pa" || compressed > 0,
            "no compressed quad"
        );
    }
}
