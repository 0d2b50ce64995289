//! `granbed-cli study work-precision --quick` (issue #8's machinery) on the
//! coarse granule: the table and the diagram are written and parse, the
//! reference has zero error, every setting is within a few per cent of it,
//! and the settings change the step count as the physics says — mass
//! scaling F by √F, twice the platen speed by 2, a smaller safety factor
//! by its ratio.

mod common;

use common::{Table, cli, parse_xml};

#[test]
fn the_quick_granule_study_writes_a_consistent_table_and_diagram() {
    let dir = common::fresh_dir("cli_study", "quick");
    let run = cli(&[
        "study",
        "work-precision",
        "--quick",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.contains("on the Pareto front"), "{}", run.stderr);
    let t = Table::read(&dir.join("work_precision.csv"));
    let names = t.text("setting");
    let steps = t.num("steps");
    let error = t.num("error_force_l2");
    let reference = t.num("reference");
    let row = |name: &str| {
        names
            .iter()
            .position(|n| *n == name)
            .unwrap_or_else(|| panic!("no row `{name}`"))
    };
    assert_eq!(reference[row("reference")], 1.0);
    assert_eq!(error[row("reference")], 0.0);
    for (i, n) in names.iter().enumerate() {
        // The one-point element against F-bar on 20 hexes: a few per cent.
        assert!(
            error[i].is_finite() && error[i] < 0.15,
            "`{n}`: force error {}",
            error[i]
        );
    }
    let ratio = |a: &str, b: &str| steps[row(a)] / steps[row(b)];
    let close = |x: f64, want: f64, what: &str| {
        assert!(
            (x / want - 1.0).abs() < 0.03,
            "{what}: {x}, expected {want}"
        );
    };
    close(
        ratio("default", "mass x10"),
        10f64.sqrt(),
        "mass scaling x10",
    );
    close(ratio("default", "speed x2"), 2.0, "speed x2");
    close(ratio("safety 0.7", "default"), 0.9 / 0.7, "safety 0.7");
    // The diagram is well-formed SVG with one point per non-reference row.
    let svg = std::fs::read_to_string(dir.join("work_precision.svg")).unwrap();
    let elements = parse_xml(&svg);
    let circles = elements.iter().filter(|e| e.name == "circle").count();
    assert_eq!(circles, names.len() - 1, "points in the diagram");
}
