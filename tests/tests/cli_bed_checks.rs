//! What `granbed-cli bed` checks and says: scene fields out of range or
//! contradicting each other are usage errors naming the field and its
//! range (a negative number on any numeric flag too); a scene file that
//! leaves out the newer numerics fields is told which values it runs with;
//! a run whose figures are not what they seem says so on stderr and in
//! `summary.json`'s `warnings` (a final strain past the target, overlaps
//! above 1 % of the element, a Kawakita fit outside the law's regime); and
//! `compression.csv` carries the bed's solid fraction for a Heckel plot. An
//! output path that is a file is refused by every command.

mod common;

use std::path::{Path, PathBuf};

use common::{Run, Table, cli, number, summary};
use granbed_cli::bed::{DEFAULT_SCENE, Scene};
use granbed_cli::model::{MeshLevel, OwnedReference};

fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_bed_checks", name)
}

/// Writes `text` as the scene file `<name>.toml` and returns its path.
fn scene_file(name: &str, text: &str) -> PathBuf {
    let path = out_dir(name).with_extension("toml");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, text).unwrap();
    path
}

/// The published scene shrunk to `granules` coarse granules in a 5 mm die
/// pressed to `strain` (snapshots within it).
fn small_scene(granules: usize, strain: &str) -> String {
    DEFAULT_SCENE
        .replace("granules = 1000", &format!("granules = {granules}"))
        .replace("mesh = \"8x2\"", "mesh = \"4x1\"")
        .replace("die_diameter_mm = 11.3", "die_diameter_mm = 5.0")
        .replace("final_strain = 0.3", &format!("final_strain = {strain}"))
        .replace(
            "snapshot_strains = [0.0, 0.1, 0.2, 0.3]",
            "snapshot_strains = [0.0]",
        )
}

fn bed(args: &[&str]) -> Run {
    let mut argv = vec!["bed", "-j", "1"];
    argv.extend_from_slice(args);
    cli(&argv)
}

/// `summary.json`'s warnings.
fn warnings(dir: &Path) -> Vec<String> {
    summary(dir)["warnings"]
        .as_array()
        .expect("summary.json has warnings")
        .iter()
        .map(|w| w.as_str().unwrap().to_owned())
        .collect()
}

#[track_caller]
fn rejected(run: &Run, needles: &[&str]) {
    assert_eq!(run.code, 2, "{}", run.stderr);
    for n in needles {
        assert!(run.stderr.contains(n), "`{n}` not in:\n{}", run.stderr);
    }
}

#[test]
fn scene_fields_out_of_range_or_contradicting_are_named() {
    let print = |text: &str| {
        let path = scene_file("print", text);
        bed(&["--print-scene", "--scene", path.to_str().unwrap()])
    };
    // A scene file that is not there: a usage error naming it.
    rejected(
        &bed(&["--print-scene", "--scene", "no/such/scene.toml"]),
        &["cannot read scene `no/such/scene.toml`"],
    );
    // Snapshot strains past the file's final strain: refused, naming the
    // file; a --strain that reaches them makes the file good (the test
    // comes after the overrides), and the printed scene keeps them.
    let late = DEFAULT_SCENE.replace(
        "snapshot_strains = [0.0, 0.1, 0.2, 0.3]",
        "snapshot_strains = [0.0, 0.3, 0.5]",
    );
    rejected(
        &print(&late),
        &["scene `", "`snapshot_strains` = 0.5", "final_strain = 0.3"],
    );
    let path = scene_file("late", &late);
    let r = bed(&[
        "--print-scene",
        "--scene",
        path.to_str().unwrap(),
        "--strain",
        "0.5",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains("snapshot_strains = [0.0, 0.3, 0.5]"),
        "{}",
        r.stdout
    );
    // The punch speed is bounded as granule's platen speed is.
    let fast = DEFAULT_SCENE.replace("punch_speed_m_s = 0.05", "punch_speed_m_s = 1e9");
    rejected(&print(&fast), &["`punch_speed_m_s`", "1e-4 <= v <= 10 m/s"]);
    let limit = DEFAULT_SCENE.replace("punch_speed_m_s = 0.05", "punch_speed_m_s = 10.0");
    assert_eq!(print(&limit).code, 0);
    // So slow that the speed watchdog would stop the settled bed at once.
    let slow = DEFAULT_SCENE.replace("punch_speed_m_s = 0.05", "punch_speed_m_s = 1e-6");
    rejected(&print(&slow), &["`punch_speed_m_s` = 1e-6", "1e-4 <= v"]);
    let limit = DEFAULT_SCENE.replace("punch_speed_m_s = 0.05", "punch_speed_m_s = 1e-4");
    assert_eq!(print(&limit).code, 0);
    // More granules than the pour's insertion lattice holds within 1 m
    // (they were poured for hours); a wider die takes them.
    rejected(
        &bed(&["--print-scene", "--granules", "100000"]),
        &[
            "`--granules 100000` is out of range",
            "at most 1 m tall",
            "1.88595 m",
        ],
    );
    let wide = bed(&[
        "--print-scene",
        "--granules",
        "5000",
        "--die-diameter-mm",
        "30",
    ]);
    assert_eq!(wide.code, 0, "{}", wide.stderr);
    // The rate check's second run at half of it would be below the limit.
    let path = scene_file("slowest", &limit);
    rejected(
        &bed(&[
            "--print-scene",
            "--rate-check",
            "--scene",
            path.to_str().unwrap(),
        ]),
        &["`--rate-check` needs a punch speed of at least 0.0002 m/s"],
    );
    // Output rows and snapshots within the final strain.
    let rows = DEFAULT_SCENE.replace(
        "output_strain_interval = 0.005",
        "output_strain_interval = 0.5",
    );
    rejected(
        &print(&rows),
        &[
            "`output_strain_interval` = 0.5",
            "1e-6 <= interval <= final_strain",
        ],
    );
    let shots = DEFAULT_SCENE.replace(
        "snapshot_strains = [0.0, 0.1, 0.2, 0.3]",
        "snapshot_strains = [0.0, 0.4]",
    );
    rejected(
        &print(&shots),
        &[
            "`snapshot_strains` = 0.4",
            "each 0 <= C <= final_strain = 0.3",
        ],
    );
    // --strain below the output interval names both.
    rejected(
        &bed(&["--print-scene", "--strain", "0.003"]),
        &[
            "`--strain 0.003` rejected",
            "`output_strain_interval` = 0.005",
        ],
    );
    // A flag that breaks another field's check is named with that field,
    // and both flags where both are given.
    rejected(
        &bed(&["--print-scene", "--hold-constraints", "false"]),
        &[
            "`--hold-constraints false` rejected",
            "`contact_search_interval` = 5",
            "1 unless hold_constraints = true",
        ],
    );
    rejected(
        &bed(&[
            "--print-scene",
            "--contact-search-interval",
            "3",
            "--hold-constraints",
            "false",
        ]),
        &["`--contact-search-interval 3` with `--hold-constraints false` rejected"],
    );
    // --strain drops the snapshots past it, so the scene printed reads
    // back as a scene file.
    let r = bed(&["--print-scene", "--strain", "0.12"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let printed = scene_file("printed", &r.stdout);
    let scene = Scene::read(&printed).unwrap();
    assert_eq!(scene.snapshot_strains, [0.0, 0.1]);
    // The punch speed and the granule size are flags too.
    let r = bed(&[
        "--print-scene",
        "--punch-speed-m-s",
        "0.02",
        "--diameter-mm",
        "0.8",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let scene = Scene::read(&scene_file("speed", &r.stdout)).unwrap();
    assert_eq!((scene.punch_speed_m_s, scene.diameter_mm), (0.02, 0.8));
}

#[test]
fn every_numeric_flag_takes_a_minus_and_names_its_range() {
    let cases: [(&str, &[&str]); 21] = [
        ("--granules", &["'--granules <N>'", "1..=100000"]),
        (
            "--diameter-mm",
            &["`--diameter-mm -1`", "0.001 <= d < 2000"],
        ),
        (
            "--punch-speed-m-s",
            &["`--punch-speed-m-s -1`", "1e-4 <= v <= 10 m/s"],
        ),
        ("--seed", &["'--seed <SEED>'", "0..=18446744073709551615"]),
        ("--strain", &["`--strain -1`", "0 < C <= 0.9"]),
        (
            "--die-diameter-mm",
            &["`--die-diameter-mm -1`", "more than 4", "4 < D <= 1000 mm"],
        ),
        (
            "--hourglass-kappa",
            &["`--hourglass-kappa -1`", "0 <= kappa <= 1"],
        ),
        (
            "--sweep-tolerance",
            &["`--sweep-tolerance -1`", "0 < t <= 0.1"],
        ),
        (
            "--face-list-skin",
            &["`--face-list-skin -1`", "0 <= s <= 1"],
        ),
        (
            "--contact-search-interval",
            &["'--contact-search-interval <N>'", "1..=10"],
        ),
        (
            "--contact-capture",
            &["`--contact-capture -1`", "0 <= c <= 0.1"],
        ),
        (
            "--exact-contact-from-strain",
            &["`--exact-contact-from-strain -1`", "0 <= C <= 1 (1: never)"],
        ),
        (
            "--kawakita-min-strain",
            &["`--kawakita-min-strain -1`", "0 <= C <= 0.9"],
        ),
        (
            "--heckel-min-strain",
            &["`--heckel-min-strain -1`", "0 <= C <= 0.9"],
        ),
        ("--stop-at-strain", &["`--stop-at-strain -1`", "0 < C <="]),
        ("--mass-scaling", &["`--mass-scaling -1`", "1 <= F <= 1e6"]),
        (
            "--selective-mass-ratio",
            &["`--selective-mass-ratio -1`", ">= 1"],
        ),
        (
            "--time-step-safety",
            &["`--time-step-safety -1`", "0 < C <= 2"],
        ),
        (
            "--time-step-floor",
            &["`--time-step-floor -1`", "0 <= r <= 1"],
        ),
        (
            "--max-mass-factor",
            &["`--max-mass-factor -1`", "1 <= k <= 1e6"],
        ),
        ("-j", &["'--threads <N>'", "0..=4096"]),
    ];
    for (flag, needles) in cases {
        let r = cli(&["bed", "--print-scene", flag, "-1"]);
        assert!(
            !r.stderr.contains("unexpected argument"),
            "{flag}: {}",
            r.stderr
        );
        rejected(&r, needles);
    }
    // Whole numbers given as decimals or exponents.
    rejected(
        &bed(&["--print-scene", "--granules", "1e3"]),
        &["'--granules <N>'", "not a whole number", "1..=100000"],
    );
    // The help tells the published time-step floor.
    let help = cli(&["bed", "--help"]).stdout;
    assert!(help.contains("The published scene's is 1"), "{help}");
}

#[test]
fn a_scene_file_without_the_newer_fields_names_the_values_it_runs_with() {
    // The full published scene: nothing to say.
    let full = scene_file("full", DEFAULT_SCENE);
    let r = bed(&["--print-scene", "--scene", full.to_str().unwrap()]);
    assert_eq!((r.code, r.stderr.as_str()), (0, ""));
    // Without the time-step floor and the held constraints (written before
    // they were fields): both named with the values used.
    let text = small_scene(20, "0.01")
        .replace("time_step_floor = 1.0\n", "")
        .replace("hold_constraints = true\n", "")
        .replace("contact_search_interval = 5\n", "")
        .replace("held_reprojection = 0.05\n", "")
        .replace("nearest_penetrated_face = true\n", "")
        .replace("exact_sweep_tolerance = 0.005\n", "")
        .replace("exact_contact_from_strain = 0.3\n", "");
    let old = scene_file("old", &text);
    let r = bed(&["--print-scene", "--scene", old.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    for needle in [
        "warning: scene",
        "omits contact_search_interval, exact_contact_from_strain, exact_sweep_tolerance, \
         held_reprojection, hold_constraints, nearest_penetrated_face, time_step_floor",
        "nearest_penetrated_face = false (published true)",
        "exact_sweep_tolerance = 0.01 (published 0.005)",
        "held_reprojection = inf (published 0.05)",
        "time_step_floor = 0.0 (published 1.0)",
        "hold_constraints = false (published true)",
        "contact_search_interval = 1 (published 5)",
        "exact_contact_from_strain = 1.0 (published 0.3)",
    ] {
        assert!(r.stderr.contains(needle), "`{needle}` not in {}", r.stderr);
    }
    // A field left out whose old value is the published one is not listed.
    let kappa = DEFAULT_SCENE.replace("hourglass_kappa = 0.05\n", "");
    let kappa = scene_file("kappa", &kappa);
    let r = bed(&["--print-scene", "--scene", kappa.to_str().unwrap()]);
    assert_eq!((r.code, r.stderr.as_str()), (0, ""));
    // A run records it in its summary too.
    let dir = out_dir("old-run");
    let r = bed(&[
        "--quiet",
        "--scene",
        old.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        warnings(&dir).iter().any(|w| w.contains("omits")),
        "{:?}",
        warnings(&dir)
    );
}

#[test]
fn a_punch_too_fast_for_the_bed_says_so() {
    // At 10 m/s one step of this bed takes the punch past the target 0.05
    // (to about 0.09), and the granules overlap deeply.
    let text = small_scene(20, "0.05").replace("punch_speed_m_s = 0.05", "punch_speed_m_s = 10.0");
    let scene = scene_file("fast", &text);
    let dir = out_dir("fast");
    let r = bed(&[
        "--quiet",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let s = summary(&dir);
    assert!(number(&s, "final_strain") > 0.05 + 0.005, "{s}");
    let w = warnings(&dir);
    let past = w
        .iter()
        .find(|w| w.contains("past the final strain 0.05 by more than one output interval"))
        .unwrap_or_else(|| panic!("{w:?}"));
    assert!(past.contains("punch_speed_m_s"), "{past}");
    assert!(number(&s, "max_penetration_rel_element") > 0.01);
    let overlap = w
        .iter()
        .find(|w| w.contains("granules overlap by up to"))
        .unwrap_or_else(|| panic!("{w:?}"));
    assert!(
        overlap.contains("--exact-contact-from-strain")
            && overlap.contains("--hold-constraints false --contact-search-interval 1"),
        "{overlap}"
    );
    // Printed on stderr (with --quiet too).
    for w in &w {
        assert!(r.stderr.contains(&format!("warning: {w}")), "{}", r.stderr);
    }
}

#[test]
fn the_kawakita_fit_outside_its_regime_is_flagged_and_the_solid_fraction_written() {
    // README's CI-sized bed: 30 coarse granules to 30 %, whose Kawakita fit
    // over C >= 0.25 gives an a outside (0, 1] and a small R^2.
    let dir = out_dir("ci");
    let mut argv = vec!["--out", dir.to_str().unwrap()];
    argv.extend_from_slice(&common::small_bed("30", "0.3"));
    let r = bed(&argv);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let s = summary(&dir);
    let (a, r2) = (
        number(&s["kawakita"], "a"),
        number(&s["kawakita"], "r_squared"),
    );
    assert!(
        !(a > 0.0 && a <= 1.0) && r2 < 0.9,
        "the bed no longer shows the case: a {a}, R^2 {r2}"
    );
    let line = r
        .stderr
        .lines()
        .find(|l| l.starts_with("bed 30 x B2"))
        .unwrap();
    assert!(line.contains(&format!("R^2 = {r2:.4}")), "{line}");
    let w = warnings(&dir);
    let fit = w
        .iter()
        .find(|w| w.contains("Kawakita fit"))
        .unwrap_or_else(|| panic!("{w:?}"));
    assert!(
        fit.contains(&format!("a = {a:.3} outside (0, 1]"))
            && fit.contains(&format!("R^2 = {r2:.3} < 0.9")),
        "{fit}"
    );
    assert!(r.stderr.contains(&format!("warning: {fit}")));
    // This bed's overlaps stay below 1 % of the element: no warning.
    assert!(number(&s, "max_penetration_rel_element") < 0.01);
    assert!(!w.iter().any(|w| w.contains("overlap")), "{w:?}");

    // The bed's solid fraction D = N eta0 V0 / (pi R_d^2 H0 (1 - C)).
    let t = Table::read(&dir.join("compression.csv"));
    let mesh = OwnedReference::sphere(0.5e-3, "4x1".parse::<MeshLevel>().unwrap(), false).unwrap();
    let (_, v0) =
        granbed_kernel::analysis::bed::surface_geometry(&mesh.positions, &mesh.quads).unwrap();
    let h0 = number(&s, "initial_bed_height_m");
    let area = core::f64::consts::PI * 2.5e-3 * 2.5e-3;
    let solid = 30.0 * 0.8 * v0;
    let d = t.num("bed_solid_fraction");
    for (c, d) in t.num("strain").iter().zip(&d) {
        common::assert_close(
            "bed_solid_fraction",
            *d,
            solid / (area * h0 * (1.0 - c)),
            1e-12,
            0.0,
        );
    }
    // A loose pour of 0.8-dense granules: about 0.6 x 0.8 at the start,
    // denser as the punch descends.
    assert!(d[0] > 0.3 && d[0] < 0.55, "{}", d[0]);
    assert!(d.windows(2).all(|w| w[1] > w[0]));
}

/// A Heckel fit the rows cannot give (K <= 0: on 20 coarse granules to 30 %
/// the pressure falls over C >= 0.25 while the bed densifies) is warned
/// about with its window and points, not left as a silent null; so is a
/// fit window that starts past the strain a finished run reached.
#[test]
fn a_heckel_fit_that_cannot_be_made_and_a_window_past_the_run_are_flagged() {
    let dir = out_dir("heckel");
    let mut argv = vec!["--out", dir.to_str().unwrap()];
    argv.extend_from_slice(&common::small_bed("20", "0.3"));
    let r = bed(&argv);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let s = summary(&dir);
    let points = number(&s["heckel"], "points");
    assert!(
        s["heckel"]["yield_pressure_pa"].is_null() && points >= 2.0,
        "the bed no longer shows the case: {}",
        s["heckel"]
    );
    let w = warnings(&dir);
    let needle = format!("no Heckel fit over C >= 0.25 ({points} points)");
    assert!(w.iter().any(|w| w.contains(&needle)), "{needle}: {w:?}");
    assert!(!w.iter().any(|w| w.contains("window starts")), "{w:?}");
    let r = bed(&[
        "--resume",
        dir.to_str().unwrap(),
        "--kawakita-min-strain",
        "0.5",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let w = warnings(&dir);
    assert!(
        w.iter()
            .any(|w| w.contains("Kawakita fit's window starts at C = 0.5")),
        "{w:?}"
    );
}

/// `--out` naming an existing file, or a path below one, is a usage error
/// (exit status 2) that says so, for every command writing an output
/// directory, before any work (it was a runtime error, exit status 1,
/// "File exists").
#[test]
fn an_output_path_that_is_a_file_is_a_usage_error() {
    let file = out_dir("a-file").with_extension("txt");
    std::fs::create_dir_all(file.parent().unwrap()).unwrap();
    std::fs::write(&file, "not a directory").unwrap();
    let out = file.to_str().unwrap();
    for argv in [
        &["granule", "--quiet", "--out", out][..],
        &["pack", "--quiet", "--out", out],
        &["bed", "--quiet", "--out", out],
        &["study", "stability", "--quiet", "--out", out],
        &["study", "work-precision", "--quiet", "--out", out],
    ] {
        let run = cli(argv);
        assert_eq!(run.code, 2, "{argv:?}: {}", run.stderr);
        assert!(
            run.stderr.contains("is a file: --out names a directory"),
            "{argv:?}: {}",
            run.stderr
        );
    }
    // A file where a parent directory would be: the same usage error.
    let below = file.join("sub");
    let below = below.to_str().unwrap();
    for argv in [
        &["granule", "--quiet", "--out", below][..],
        &["bed", "--quiet", "--out", below],
    ] {
        let run = cli(argv);
        assert_eq!(run.code, 2, "{argv:?}: {}", run.stderr);
        assert!(
            run.stderr.contains("cannot be made"),
            "{argv:?}: {}",
            run.stderr
        );
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "not a directory");
}

/// summary.json keeps the scene as run exactly (`scene_toml`, read back by
/// `--scene`), where its JSON object can only say `null` for ∞.
#[test]
fn the_summary_keeps_the_scene_exactly() {
    let dir = out_dir("scene-toml");
    let mut argv = vec!["--out", dir.to_str().unwrap(), "--held-reprojection", "inf"];
    argv.extend_from_slice(&common::small_bed("8", "0.02"));
    let r = bed(&argv);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let s = summary(&dir);
    assert!(s["scene"]["held_reprojection"].is_null());
    let scene = Scene::from_toml(s["scene_toml"].as_str().unwrap()).unwrap();
    assert_eq!(scene.held_reprojection, f64::INFINITY);
    assert_eq!(scene.granules, 8);
}

/// A scene whose granules' own buffers exceed the machine's memory is
/// refused by name before the pour (it was killed for want of memory after
/// it, without a message): 100 000 granules of 32x8 need about 1.8 TB.
#[test]
fn a_scene_too_large_for_the_memory_is_refused_before_the_pour() {
    let dir = out_dir("too-large");
    let out = dir.to_str().unwrap();
    let huge = [
        "--quiet",
        "--granules",
        "100000",
        "--die-diameter-mm",
        "200",
        "--mesh",
        "32x8",
        "--out",
        out,
    ];
    rejected(
        &bed(&huge),
        &[
            "`granules` = 100000 on the `mesh` 32x8 need at least",
            "GB of memory: use fewer granules or a coarser mesh",
        ],
    );
    assert!(
        !dir.join("checkpoint.bin").exists() && !dir.join("packing.csv").exists(),
        "nothing is poured or written"
    );
    // A `--types` series, whose members share one pour, checks them
    // before it.
    let series = [&huge[..], &["--types", "A2,B2"]].concat();
    rejected(
        &bed(&series),
        &["A2", "`granules` = 100000 on the `mesh` 32x8 need at least"],
    );
    assert!(
        !dir.join("series.json").exists(),
        "nothing is poured or written"
    );
}
