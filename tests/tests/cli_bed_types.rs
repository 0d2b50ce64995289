//! `granbed-cli bed --types`: several granule types compressed from ONE
//! pour. A CI-sized bed (30 coarse 4x1 granules in a 5 mm die, to 15 %
//! strain) with A2, B2, C2 — one η0, so the pour is the same for all and
//! only the yield stress differs (10, 30, 100 kPa): the punch pressure at
//! the final strain is ordered A2 < B2 < C2 (a harder granule makes a
//! stiffer bed; measured about 1.4, 3.1, 5.0 kPa). Every type has its own
//! outputs, and `comparison.csv` holds their summary values in the order
//! given. Usage errors name the flag.

mod common;

use std::path::PathBuf;

use common::{Table, cli, number, summary};

fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_bed_types", name)
}

const TYPES: [&str; 3] = ["A2", "B2", "C2"];

/// `comparison.csv` column → `summary.json` field.
const SAME_AS_SUMMARY: [(&str, &str); 8] = [
    ("initial_solid_fraction", "initial_solid_fraction"),
    ("max_pressure_pa", "max_pressure_pa"),
    ("final_strain", "final_strain"),
    ("final_pressure_pa", "final_pressure_pa"),
    ("final_relative_density", "final_relative_density"),
    ("final_coordination", "final_coordination"),
    ("yield_stress_pa", "yield_stress_pa"),
    ("eta0", "eta0"),
];

#[test]
fn three_types_from_one_pour_are_ordered_by_yield_stress() {
    let dir = out_dir("a2b2c2");
    let mut argv = vec![
        "bed",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--types",
        "A2,b2,C2",
    ];
    argv.extend_from_slice(&common::small_bed("30", "0.15"));
    let run = cli(&argv);
    assert_eq!(run.code, 0, "bed --types failed:\n{}", run.stderr);

    let table = Table::read(&dir.join("comparison.csv"));
    assert_eq!(table.text("type"), TYPES, "rows in the order given");
    let summaries: Vec<_> = TYPES
        .iter()
        .map(|t| {
            let sub = dir.join(t);
            assert!(
                sub.join("compression.csv").is_file(),
                "{t}: no compression.csv"
            );
            let s = summary(&sub);
            assert_eq!(s["scene"]["granule_type"], *t);
            assert!(s["error"].is_null(), "{t}: {}", s["error"]);
            s
        })
        .collect();
    // The table's numbers are the summaries' values, bit for bit.
    for (column, field) in SAME_AS_SUMMARY {
        let values = table.num(column);
        for ((t, s), v) in TYPES.iter().zip(&summaries).zip(values) {
            assert_eq!(v, number(s, field), "{t}: {column}");
        }
    }
    // The withdrawal's figures (the published scene unloads): NaN in the
    // table where the summary has none.
    for column in ["elastic_recovery", "plasticity_factor"] {
        let values = table.num(column);
        for ((t, s), v) in TYPES.iter().zip(&summaries).zip(values) {
            match s["unloading"][column].as_f64() {
                Some(x) => assert_eq!(v, x, "{t}: {column}"),
                None => assert!(v.is_nan(), "{t}: {column} {v}"),
            }
        }
    }
    for ((t, s), v) in TYPES
        .iter()
        .zip(&summaries)
        .zip(table.num("kawakita_points"))
    {
        assert_eq!(v, s["kawakita"]["points"].as_f64().unwrap(), "{t}");
    }
    // The certificate's verdict, 1 or 0, is the summary's.
    for ((t, s), v) in TYPES
        .iter()
        .zip(&summaries)
        .zip(table.num("quasi_static_passed"))
    {
        let passed = s["quasi_static"]["passed"].as_bool().unwrap();
        assert_eq!(v, if passed { 1.0 } else { 0.0 }, "{t}");
    }
    assert_eq!(table.num("yield_stress_pa"), [10e3, 30e3, 100e3]);
    assert_eq!(table.num("eta0"), [0.8; 3]);

    // One pour: the same bed height for every type.
    let h0: Vec<f64> = summaries
        .iter()
        .map(|s| number(s, "initial_bed_height_m"))
        .collect();
    assert!(h0.iter().all(|&h| h == h0[0]), "bed heights {h0:?}");

    // Each type's final pressure is the last row of its compression.csv,
    // reached at the final strain, and they rise with the yield stress.
    let finals: Vec<f64> = TYPES
        .iter()
        .map(|t| {
            let c = Table::read(&dir.join(t).join("compression.csv"));
            assert!(*c.num("strain").last().unwrap() >= 0.15 - 1e-9, "{t}");
            *c.num("upper_pressure_pa").last().unwrap()
        })
        .collect();
    assert_eq!(finals, table.num("final_pressure_pa"));
    assert!(
        finals[0] > 0.0 && finals[0] < finals[1] && finals[1] < finals[2],
        "final pressures A2, B2, C2 not increasing: {finals:?}"
    );

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("comparison.json")).unwrap())
            .unwrap();
    assert_eq!(
        json["pour_granule_type"], "B2",
        "the scene's type is listed"
    );
    assert_eq!(json["types"].as_array().unwrap().len(), 3);
    // The series' page: the three overlays inline, one linked row per type.
    let report = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert_eq!(report.matches("<svg").count(), 3);
    for t in TYPES {
        assert!(
            report.contains(&format!("<tr><td><a href=\"{t}/report.html\">{t}</a>"))
                || report.contains(&format!(
                    "<tr class=\"doubt\"><td><a href=\"{t}/report.html\">{t}</a>"
                )),
            "report.html lacks the row of {t}"
        );
    }
    for name in [
        "comparison_pressure.svg",
        "comparison_density.svg",
        "comparison_profile.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(svg.starts_with("<svg"), "{name}");
        // Each type's legend, marked as its row of the table says.
        for (t, row) in TYPES.iter().zip(json["types"].as_array().unwrap()) {
            assert_eq!(row["type"], *t);
            let label = if !row["error"].is_null() {
                format!("{t} (failed)")
            } else if row["quasi_static_passed"] == false {
                format!("{t} (not quasi-static)")
            } else {
                t.to_string()
            };
            assert!(
                svg.contains(&format!(">\n{label}\n</text>")),
                "{name} lacks the legend {label}"
            );
        }
    }
}

#[test]
fn bad_type_lists_and_conflicts_are_usage_errors() {
    let dir = out_dir("bad");
    let out = dir.to_str().unwrap();
    let run = cli(&["bed", "--out", out, "--types", "A2,D7"]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("--types")
            && run.stderr.contains("A1, A2")
            && run.stderr.contains("all"),
        "{}",
        run.stderr
    );
    let run = cli(&["bed", "--out", out, "--types", "A2,a2"]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("twice"), "{}", run.stderr);
    for extra in [
        &["--stop-at-strain", "0.1"][..],
        &["--resume", out][..],
        &["--type", "B2"][..],
    ] {
        let mut argv = vec!["bed", "--types", "all"];
        argv.extend_from_slice(extra);
        let run = cli(&argv);
        assert_eq!(run.code, 2, "{extra:?}: {}", run.stderr);
        assert!(
            run.stderr.contains("--types") && run.stderr.contains(extra[0]),
            "{extra:?}: {}",
            run.stderr
        );
    }
    // A scene whose material override leaves two listed types one
    // material: refused before the pour, naming the field.
    let scene = out_dir("scenes").join("yield.toml");
    common::write_scene_with_material(&scene, "yield_stress_pa = 50000.0");
    let run = cli(&[
        "bed",
        "--out",
        out,
        "--scene",
        scene.to_str().unwrap(),
        "--types",
        "A2,C2",
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("material.yield_stress_pa") && run.stderr.contains("A2 and C2"),
        "{}",
        run.stderr
    );
    assert!(!dir.exists(), "a usage error wrote {}", dir.display());
}
