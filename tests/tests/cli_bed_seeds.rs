//! `granbed-cli bed --seeds`: one scene poured and compressed once per
//! seed, and the run-to-run spread of its figures (physics.md §8 P2). On a
//! CI-sized bed (20 coarse granules in a 5 mm die, to 30 %): each seed's
//! run is the run of `--seed S` alone, bit for bit; `seeds.csv` holds each
//! run's summary values; `seeds_spread.csv` holds their mean, sample
//! standard deviation, min and max (fits the summary warns about left
//! out), checked against the table here; and different pours differ.

mod common;

use std::path::PathBuf;

use common::{Table, cli, number, summary};

fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_bed_seeds", name)
}

const BED: [&str; 8] = common::small_bed("20", "0.3");

#[test]
fn each_seed_is_its_own_run_and_the_spread_is_of_their_figures() {
    let dir = out_dir("s12");
    let mut argv = vec![
        "bed",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--seeds",
        "2,1",
    ];
    argv.extend_from_slice(&BED);
    let run = cli(&argv);
    assert_eq!(run.code, 0, "bed --seeds failed:\n{}", run.stderr);

    // Seed 2 alone: the same compression table, byte for byte.
    let alone = out_dir("alone");
    let mut argv = vec![
        "bed",
        "--quiet",
        "--out",
        alone.to_str().unwrap(),
        "--seed",
        "2",
    ];
    argv.extend_from_slice(&BED);
    assert_eq!(cli(&argv).code, 0);
    assert_eq!(
        std::fs::read(dir.join("seed_2/compression.csv")).unwrap(),
        std::fs::read(alone.join("compression.csv")).unwrap()
    );

    let table = Table::read(&dir.join("seeds.csv"));
    assert_eq!(table.num("seed"), [2.0, 1.0], "rows in the order given");
    let summaries: Vec<_> = ["seed_2", "seed_1"]
        .iter()
        .map(|d| summary(&dir.join(d)))
        .collect();
    for (s, seed) in summaries.iter().zip([2, 1]) {
        assert_eq!(s["scene"]["seed"], seed);
    }
    for field in [
        "initial_solid_fraction",
        "max_pressure_pa",
        "final_pressure_pa",
        "final_relative_density",
        "final_coordination",
        "kawakita_a",
    ] {
        let column = table.num(field);
        for (s, v) in summaries.iter().zip(&column) {
            assert_eq!(*v, number(s, field), "{field}");
        }
    }
    // Two pours, two beds.
    let d0 = table.num("initial_solid_fraction");
    assert_ne!(d0[0], d0[1]);

    // The spread of each figure from the rows.
    // The series' page links the runs in the order given and shows the
    // spread.
    let report = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let (at2, at1) = (
        report.find("<a href=\"seed_2/report.html\">seed_2</a></td>"),
        report.find("<a href=\"seed_1/report.html\">seed_1</a></td>"),
    );
    assert!(
        at2.is_some() && at1.is_some() && at2 < at1,
        "rows: {report}"
    );
    assert!(report.contains("<h2>Spread over the runs</h2>"));
    assert_eq!(report.matches("<svg").count(), 3);
    assert!(dir.join("seeds_profile.svg").is_file());

    let spread = Table::read(&dir.join("seeds_spread.csv"));
    let figures = spread.text("figure");
    assert!(
        figures.contains(&"kawakita_inv_b_pa") && figures.contains(&"heckel_yield_pressure_pa")
    );
    let (runs, mean, std, min, max) = (
        spread.num("runs"),
        spread.num("mean"),
        spread.num("std"),
        spread.num("min"),
        spread.num("max"),
    );
    // A fit its run's summary warns about is left out: Kawakita with a
    // outside (0, 1], 1/b <= 0 or R^2 < 0.9; Heckel with R^2 < 0.9.
    let (ka, kb, kr, hr) = (
        table.num("kawakita_a"),
        table.num("kawakita_inv_b_pa"),
        table.num("kawakita_r_squared"),
        table.num("heckel_r_squared"),
    );
    let described = |figure: &str, k: usize| match figure {
        "kawakita_a" | "kawakita_inv_b_pa" => {
            ka[k] > 0.0 && ka[k] <= 1.0 && kb[k] > 0.0 && kr[k] >= 0.9
        }
        "heckel_yield_pressure_pa" => hr[k] >= 0.9,
        _ => true,
    };
    // The table says which fits are material figures, by the same rule.
    for (k, summary) in summaries.iter().enumerate() {
        let ok = |column: &str| table.num(column)[k] == 1.0;
        assert_eq!(ok("kawakita_ok"), described("kawakita_a", k), "row {k}");
        assert_eq!(
            ok("heckel_ok"),
            described("heckel_yield_pressure_pa", k),
            "row {k}"
        );
        let warned = summary["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("Kawakita fit"));
        assert_eq!(
            ok("kawakita_ok"),
            !warned,
            "row {k}: the summary's warnings"
        );
    }
    for (i, figure) in figures.iter().enumerate() {
        let v: Vec<f64> = (0..2)
            .map(|k| table.num(figure)[k])
            .enumerate()
            .filter(|&(k, x)| x.is_finite() && described(figure, k))
            .map(|(_, x)| x)
            .collect();
        assert_eq!(runs[i], v.len() as f64, "{figure}");
        assert_eq!(spread.num("left_out")[i], 2.0 - v.len() as f64, "{figure}");
        if v.len() < 2 {
            continue;
        }
        let m = (v[0] + v[1]) / 2.0;
        let s = ((v[0] - m).powi(2) + (v[1] - m).powi(2)).sqrt();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs().max(1e-300);
        assert!(close(mean[i], m), "{figure}: mean {} against {m}", mean[i]);
        assert!(close(std[i], s), "{figure}: std {} against {s}", std[i]);
        assert_eq!(min[i], v[0].min(v[1]), "{figure}");
        assert_eq!(max[i], v[0].max(v[1]), "{figure}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("seeds.json")).unwrap()).unwrap();
    assert_eq!(json["seeds"].as_array().unwrap().len(), 2);
    assert_eq!(json["spread"].as_array().unwrap().len(), figures.len());
    for svg in ["seeds_pressure.svg", "seeds_density.svg"] {
        let text = std::fs::read_to_string(dir.join(svg)).unwrap();
        assert!(text.contains("seed 1") && text.contains("seed 2"), "{svg}");
    }
}

#[test]
fn seed_lists_are_checked_and_exclusive() {
    let dir = out_dir("bad");
    let out = dir.to_str().unwrap();
    for (flags, needle) in [
        (&["--seeds", "1,1"][..], "listed twice"),
        (&["--seeds", "1,-3"], "`-3`"),
        (&["--seeds", "1,2", "--seed", "4"], "--seed"),
        (&["--seeds", "1,2", "--types", "A2,B2"], "--types"),
        (&["--seeds", "1,2", "--resume", out], "--resume"),
    ] {
        let mut argv = vec!["bed", "--quiet", "--out", out];
        argv.extend_from_slice(flags);
        let run = cli(&argv);
        assert_eq!(run.code, 2, "{flags:?}: {}", run.stderr);
        assert!(run.stderr.contains(needle), "{flags:?}: {}", run.stderr);
    }
}
