//! `granbed-cli pack`: the pour of rigid spheres into the die, driven end to
//! end through `granbed_cli::run` and `granbed_cli::error::report` with
//! in-memory streams (what the binary's `main` does; see cli_point.rs), plus
//! the round trip of the packing file it hands over to the bed compression.
//!
//! Beds are small so each pour takes about a second: 100 granules in a 5 mm
//! die stand about 5 mm tall, enough for an interior region (2d from the
//! wall, the floor and the top). Every run writes to its own directory
//! under Cargo's per-target temporary directory.

mod common;

use std::path::{Path, PathBuf};

use common::{Element, Run, Table, assert_close, cli, number, parse_xml, summary};
use granbed_cli::pack::measures::{self, Region};
use granbed_cli::pack::{outputs, read_packing};
use serde_json::Value;

/// A fresh (emptied, not created) output directory named `name`.
fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_pack", name)
}

/// Runs `granbed-cli pack --out DIR ARGS`.
fn pack(dir: &Path, args: &[&str]) -> Run {
    let mut argv = vec!["pack", "--out", dir.to_str().expect("UTF-8 path")];
    argv.extend_from_slice(args);
    cli(&argv)
}

/// Runs `granbed-cli pack --out DIR ARGS` and asserts success.
fn pack_ok(dir: &Path, args: &[&str]) -> Run {
    let run = pack(dir, args);
    assert_eq!(run.code, 0, "pack {args:?} failed:\n{}", run.stderr);
    run
}

/// Keys `summary.json` must have.
const SUMMARY_KEYS: [&str; 30] = [
    "format",
    "format_version",
    "granbed_version",
    "granule_type",
    "eta0",
    "true_density_kg_m3",
    "density_kg_m3",
    "granules",
    "diameter_m",
    "die_diameter_m",
    "youngs_modulus_pa",
    "friction_particle",
    "friction_wall",
    "max_time_s",
    "seed",
    "settled",
    "bed_height_m",
    "packing_fraction",
    "interior_packing_fraction",
    "interior_region",
    "sphere_contacts",
    "coordination_number",
    "floor_contacts",
    "die_contacts",
    "max_overlap_m",
    "settle_time_s",
    "steps",
    "dt_s",
    "wall_time_s",
    "force_balance_rel",
];

/// The values of the `DataArray` named `name`.
fn data_array<'a>(elements: &'a [Element], name: &str) -> Vec<&'a str> {
    let e = elements
        .iter()
        .find(|e| e.name == "DataArray" && e.attrs.get("Name").map(String::as_str) == Some(name))
        .unwrap_or_else(|| panic!("no DataArray {name}"));
    e.text.split_whitespace().collect()
}

/// The standard small bed of these tests.
const SMALL: [&str; 6] = ["--granules", "100", "--die-diameter-mm", "5", "--seed", "3"];

#[test]
fn outputs_exist_parse_and_agree() {
    let dir = out_dir("outputs");
    let run = pack_ok(&dir, &SMALL);
    let line = run
        .stderr
        .lines()
        .find(|l| l.starts_with("pack B2: 100 granules at rest"))
        .unwrap_or_else(|| panic!("no summary line in:\n{}", run.stderr));
    for part in ["bed height", "packing fraction", "interior", "coordination"] {
        assert!(line.contains(part), "{part} missing from {line:?}");
    }

    // packing.csv: the header, one row per granule, and the reader.
    let t = Table::read(&dir.join("packing.csv"));
    assert_eq!(t.header, "x_m,y_m,z_m,radius_m");
    assert_eq!(t.cells.len(), 100);
    let spheres = read_packing(&dir.join("packing.csv")).unwrap();
    assert_eq!(spheres.len(), 100);
    let (x, r): (Vec<[f64; 3]>, f64) = (spheres.iter().map(|s| s.0).collect(), 0.5e-3);
    assert!(spheres.iter().all(|s| s.1 == r));
    for (row, c) in t.rows().iter().zip(&x) {
        assert_eq!(&row[..3], c);
    }
    // Written again, the packing is the same file byte for byte.
    let again = dir.join("again.csv");
    outputs::write_packing(&again, &x, r).unwrap();
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(dir.join("packing.csv")).unwrap()
    );

    // summary.json: every key, the inputs, and the measures recomputed from
    // the packing file.
    let s = summary(&dir);
    for key in SUMMARY_KEYS {
        assert!(s.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(s["format"], "granbed-pack-summary");
    assert_eq!(s["granule_type"], "B2");
    assert_eq!(s["settled"], true);
    assert_eq!(s["error"], Value::Null);
    assert_eq!(s["seed"], 3);
    assert_eq!(s["granules"], 100);
    assert_eq!(number(&s, "die_diameter_m"), 5e-3);
    assert_eq!(number(&s, "diameter_m"), 1e-3);
    assert_eq!(number(&s, "density_kg_m3"), 0.8 * 1500.0);
    assert_eq!(number(&s, "youngs_modulus_pa"), 100e6);
    assert_eq!(number(&s, "friction_particle"), 0.1);

    let height = x.iter().map(|c| c[2] + r).fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(number(&s, "bed_height_m"), height, "bed height = max z + r");
    let die_r = 2.5e-3;
    let phi = 100.0 * (4.0 / 3.0) * core::f64::consts::PI * r.powi(3)
        / (core::f64::consts::PI * die_r * die_r * height);
    assert_close(
        "packing_fraction",
        number(&s, "packing_fraction"),
        phi,
        1e-14,
        0.0,
    );
    assert!((0.4..0.6).contains(&phi), "packing fraction {phi}");

    // Contacts by brute force over all pairs of the file.
    let (mut contacts, mut deepest) = (0, 0.0_f64);
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            let overlap = 2.0 * r - measures::distance(&x[i], &x[j]);
            if overlap > 0.0 {
                contacts += 1;
                deepest = deepest.max(overlap);
            }
        }
    }
    assert_eq!(s["sphere_contacts"], contacts);
    assert_eq!(
        number(&s, "coordination_number"),
        2.0 * contacts as f64 / 100.0
    );
    assert!(
        contacts > 100,
        "a settled bed has Z > 2: {contacts} contacts"
    );
    let floor = x.iter().filter(|c| c[2] < r).count();
    let die = x.iter().filter(|c| c[0].hypot(c[1]) + r > die_r).count();
    assert_eq!(
        (s["floor_contacts"].clone(), s["die_contacts"].clone()),
        (floor.into(), die.into())
    );
    assert_eq!(number(&s, "max_sphere_overlap_m"), deepest);
    let max_overlap = number(&s, "max_overlap_m");
    assert!(
        max_overlap >= deepest && max_overlap < 0.3e-6,
        "{max_overlap:e}"
    );

    // Interior region 2d from the wall, the floor and the top.
    let region = &s["interior_region"];
    assert_eq!(number(region, "radius_m"), die_r - 2e-3);
    assert_eq!(number(region, "z_lo_m"), 2e-3);
    assert_eq!(number(region, "z_hi_m"), height - 2e-3);
    let interior = Region::interior(die_r, height, 2e-3)
        .unwrap()
        .packing_fraction(&x, r);
    assert_eq!(number(&s, "interior_packing_fraction"), interior);
    assert!((0.4..0.75).contains(&interior), "interior {interior}");

    // At rest: the floor and the wall carry the weight.
    let balance = number(&s, "force_balance_rel");
    assert!(balance.abs() < 1e-3, "force balance {balance:e}");
    assert!(
        number(&s, "settle_time_s") > 0.05,
        "rest is checked once the ramp has begun"
    );
    assert!(number(&s, "dt_s") > 0.0 && number(&s, "steps") > 0.0);

    // packing.vtu: well-formed, one vertex per granule at the same centres.
    let xml = std::fs::read_to_string(dir.join("packing.vtu")).unwrap();
    let elements = parse_xml(&xml);
    let piece = elements.iter().find(|e| e.name == "Piece").unwrap();
    assert_eq!(piece.attrs["NumberOfPoints"], "100");
    assert_eq!(piece.attrs["NumberOfCells"], "100");
    let root = elements.last().unwrap();
    assert_eq!(root.name, "VTKFile");
    assert_eq!(root.attrs["type"], "UnstructuredGrid");
    let points: Vec<f64> = data_array(&elements, "Points")
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(
        points,
        x.concat(),
        "VTU points are the CSV centres, bit for bit"
    );
    let radius = data_array(&elements, "radius");
    assert_eq!(radius.len(), 100);
    assert!(radius.iter().all(|v| v.parse::<f64>().unwrap() == r));
    let ids: Vec<String> = (0..100).map(|i| i.to_string()).collect();
    assert_eq!(data_array(&elements, "id"), ids);
    assert_eq!(data_array(&elements, "connectivity"), ids);
    assert_eq!(data_array(&elements, "types"), ["1"; 100]);
}

#[test]
fn packing_round_trips_exactly() {
    let dir = out_dir("round-trip");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("packing.csv");
    let tricky = [
        [0.1, -0.0, 1.0 / 3.0],
        [5e-324, f64::MIN_POSITIVE, 1e-5],
        [-2.5e-4, 9.999_999_999_999_999e14, 1e15],
        [core::f64::consts::PI * 1e-3, -1e-300, 123_456.789],
    ];
    let radius = 0.1 + 0.2;
    outputs::write_packing(&path, &tricky, radius).unwrap();
    let back = read_packing(&path).unwrap();
    assert_eq!(back.len(), tricky.len());
    for (b, x) in back.iter().zip(&tricky) {
        let bits = |v: &[f64; 3]| v.map(f64::to_bits);
        assert_eq!(bits(&b.0), bits(x));
        assert_eq!(b.1.to_bits(), radius.to_bits());
    }
    // A damaged file names itself and the line.
    std::fs::write(&path, "x_m,y_m,z_m,radius_m\n1,2,3,0.5\n1,2,x,0.5\n").unwrap();
    let err = format!("{:#}", read_packing(&path).unwrap_err());
    assert!(
        err.contains("packing.csv") && err.contains("line 3"),
        "{err}"
    );
}

#[test]
fn same_seed_same_bytes() {
    let bytes = |name: &str, seed: &str| {
        let dir = out_dir(name);
        pack_ok(
            &dir,
            &[
                "--granules",
                "40",
                "--die-diameter-mm",
                "5",
                "--seed",
                seed,
                "--quiet",
            ],
        );
        std::fs::read(dir.join("packing.csv")).unwrap()
    };
    let a = bytes("seed-a", "11");
    assert_eq!(a, bytes("seed-b", "11"), "same seed, same packing.csv");
    assert_ne!(a, bytes("seed-c", "12"), "another seed, another packing");
}

#[test]
fn quiet_prints_nothing() {
    let dir = out_dir("quiet");
    let run = pack_ok(&dir, &["--granules", "5", "--quiet"]);
    assert_eq!((run.stdout.as_str(), run.stderr.as_str()), ("", ""));
    let s = summary(&dir);
    // Five spheres on the floor of the wide die: no interior region.
    assert_eq!(s["interior_packing_fraction"], Value::Null);
    assert_eq!(s["floor_contacts"], 5);
}

#[test]
fn bad_input_exits_2_naming_the_flag() {
    let cases: [(&[&str], &str); 21] = [
        // Whole numbers: the flag and the allowed range, whatever the typo.
        (
            &["--granules", "0"],
            "'--granules <N>': out of range (allowed: whole numbers 1..=100000)",
        ),
        (
            &["--granules", "-3"],
            "'--granules <N>': out of range (allowed: whole numbers 1..=100000)",
        ),
        (
            &["--granules", "1e3"],
            "'--granules <N>': not a whole number (allowed: whole numbers 1..=100000)",
        ),
        (
            &["--granules", "1.5"],
            "'--granules <N>': not a whole number (allowed: whole numbers 1..=100000)",
        ),
        (&["--die-diameter-mm", "1.5"], "`--die-diameter-mm 1.5`"),
        (
            &["--seed", "abc"],
            "'--seed <SEED>': not a whole number (allowed: whole numbers 0..=",
        ),
        (
            &["--seed", "-1"],
            "'--seed <SEED>': out of range (allowed: whole numbers 0..=",
        ),
        (&["--seed", "1.5"], "'--seed <SEED>': not a whole number"),
        (&["--diameter-mm", "0"], "`--diameter-mm 0`"),
        (&["--youngs-modulus-mpa", "-5"], "`--youngs-modulus-mpa -5`"),
        // Too soft to rest without deep overlaps, too stiff to finish.
        (
            &["--youngs-modulus-mpa", "1e-12"],
            "`--youngs-modulus-mpa 1e-12` is out of range (allowed: 1 <= E <= 1e5 MPa)",
        ),
        (
            &["--youngs-modulus-mpa", "1e9"],
            "(allowed: 1 <= E <= 1e5 MPa)",
        ),
        (
            &["--die-diameter-mm", "1e-9"],
            "allowed: more than 4 granule diameters, here more than 4 mm for `--diameter-mm 1`",
        ),
        (
            &["--diameter-mm", "3000"],
            "`--diameter-mm 3000` is out of range (allowed: 0.001 <= d < 2000 mm)",
        ),
        // Vast or tiny sizes are refused before the lattice is walked
        // (they ran for ever).
        (
            &["--diameter-mm", "1e-160"],
            "`--diameter-mm 1e-160` is out of range",
        ),
        (
            &["--die-diameter-mm", "1e200"],
            "`--die-diameter-mm 1e200` is too wide",
        ),
        (&["--max-time-s", "0.2"], "`--max-time-s 0.2`"),
        (&["--friction", "-1"], "`--friction -1`"),
        (&["--eta0", "1.5"], "`--eta0 1.5`"),
        (&["--type", "Z9"], "--type"),
        (&["--granules", "100000"], "`--granules`"),
    ];
    for (args, flag) in cases {
        let dir = out_dir("bad");
        let run = pack(&dir, args);
        assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
        assert!(
            run.stderr.contains(flag),
            "{args:?}: {flag} not in {}",
            run.stderr
        );
        assert!(!dir.exists(), "{args:?}: nothing is written");
    }
    let run = pack(&out_dir("bad"), &["--granules", "100000"]);
    assert!(
        run.stderr.contains("do not fit in the die"),
        "{}",
        run.stderr
    );
}

#[test]
fn unsettled_pour_writes_outputs_and_fails() {
    // A 46 cm column of 2000 granules in a 4.1 mm die (5 per layer) is still
    // falling at 0.31 s (its top needs 0.31 s to reach the floor in free
    // fall, and the dissipation ramp ends at 0.30 s); a soft contact keeps
    // the run short (~5 s).
    let dir = out_dir("unsettled");
    let run = pack(
        &dir,
        &[
            "--granules",
            "2000",
            "--die-diameter-mm",
            "4.1",
            "--youngs-modulus-mpa",
            "1",
            "--max-time-s",
            "0.31",
        ],
    );
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(run.stderr.contains("NOT at rest"), "{}", run.stderr);
    assert!(
        run.stderr.contains("did not come to rest"),
        "{}",
        run.stderr
    );
    let s = summary(&dir);
    assert_eq!(s["settled"], false);
    assert_eq!(s["settle_time_s"], Value::Null);
    assert!(
        s["error"]
            .as_str()
            .unwrap()
            .contains("did not come to rest")
    );
    assert_eq!(read_packing(&dir.join("packing.csv")).unwrap().len(), 2000);
    assert!(dir.join("packing.vtu").exists());
}
