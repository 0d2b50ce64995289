//! `granbed-cli granule`: the single-granule platen experiment, driven end
//! to end through `granbed_cli::run` and `granbed_cli::error::report` with
//! in-memory streams (what the binary's `main` does; see cli_point.rs).
//!
//! Runs use the coarse 4x1 mesh (20 octant hexes) to small strains so each
//! takes a fraction of a second; the hourglass check uses the standard 8x2
//! mesh (see `energy_balances_and_hourglass_is_small`). Every run writes to
//! its own directory under Cargo's per-target temporary directory.

mod common;

use std::path::{Path, PathBuf};

use common::{Run, Table, assert_close, cli, number, summary};
use serde_json::Value;

/// A fresh (emptied) output directory named `name`.
fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_granule", name)
}

/// Runs `granbed-cli granule ARGS --out DIR` and asserts success.
fn granule_ok(dir: &Path, args: &[&str]) -> Run {
    let mut argv = vec!["granule", "--out", dir.to_str().expect("UTF-8 path")];
    argv.extend_from_slice(args);
    let run = cli(&argv);
    assert_eq!(run.code, 0, "granule {args:?} failed:\n{}", run.stderr);
    run
}

/// The header `force_displacement.csv` must have, in this order.
const FORCE_HEADER: &str = "time_s,displacement_m,strain,force_n,force_upper_n,force_lower_n,\
                            kinetic_j,internal_work_j,elastic_j,plastic_j,hourglass_j,damping_j,\
                            contact_work_j,gravity_work_j,platen_work_j,min_jacobian,dt_s,steps";

/// Keys `summary.json` must have.
const SUMMARY_KEYS: [&str; 46] = [
    "format",
    "format_version",
    "granbed_version",
    "granule_type",
    "mesh",
    "symmetry",
    "mesh_nodes",
    "mesh_hexes",
    "diameter_m",
    "youngs_modulus_pa",
    "poisson_ratio",
    "yield_stress_pa",
    "eta0",
    "cp",
    "eta_c",
    "true_density_kg_m3",
    "friction",
    "target_strain",
    "approach_speed_m_s",
    "damping_ratio",
    "hourglass_kappa",
    "literal_return",
    "time_step_safety",
    "output_strain_interval",
    "gravity_m_s2",
    "mass_scaling",
    "sigma_est_pa",
    "sigma_eff0_pa",
    "slope_n_per_m",
    "fit_r_squared",
    "fit_points",
    "steps",
    "dt_s",
    "element_steps",
    "wall_time_s",
    "ns_per_element_step",
    "energy_residual_rel",
    "return_map_gap_rel",
    "hourglass_energy_rel",
    "damping_rel",
    "min_jacobian",
    "quasi_static",
    "final_strain",
    "max_force_n",
    "notes",
    "error",
];

/// The coarse quick run most tests use: B2, 4x1 octant, to 15 % strain
/// (11 samples in the σ_est range 0.1–0.4).
const QUICK: [&str; 6] = ["--type", "B2", "--mesh", "4x1", "--strain", "0.15"];

#[test]
fn outputs_exist_and_parse() {
    let dir = out_dir("outputs");
    let run = granule_ok(&dir, &QUICK);
    let line = run
        .stderr
        .lines()
        .find(|l| l.starts_with("granule B2 (4x1 octant)"))
        .unwrap_or_else(|| panic!("no summary line in:\n{}", run.stderr));
    for part in ["sigma_est", "sigma_eff0", "steps", "ns/element-step"] {
        assert!(line.contains(part), "{part} missing from {line:?}");
    }

    let t = Table::read(&dir.join("force_displacement.csv"));
    assert_eq!(t.header, FORCE_HEADER);
    // Samples every 0.005 strain to 0.15, plus the unloaded row at t = 0.
    assert_eq!(t.cells.len(), 31);
    assert_eq!(t.num("time_s")[0], 0.0);
    assert_eq!(t.num("force_n")[0], 0.0);
    assert!(*t.num("strain").last().unwrap() >= 0.15);

    let s = summary(&dir);
    for key in SUMMARY_KEYS {
        assert!(s.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(s["format"], "granbed-granule-summary");
    assert_eq!(s["granule_type"], "B2");
    assert_eq!(s["mesh"], "4x1");
    assert_eq!(s["symmetry"], "octant");
    assert_eq!(s["mesh_hexes"], 20);
    assert_eq!(s["error"], Value::Null);
    assert_eq!(s["granbed_version"], env!("CARGO_PKG_VERSION"));
    // The run ended before strain 0.4: σ_est is fitted over 0.1–0.15 and
    // a note says so.
    assert!(s["sigma_est_pa"].as_f64().is_some());
    assert!(s["notes"][0].as_str().unwrap().contains("only"), "{s}");
    // The range reported is the one fitted: the samples from 0.1 to the
    // end (0.15), not the nominal 0.1-0.4; stderr warns of it too.
    let range: Vec<f64> = s["sigma_est_strain_range"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let strains = t.num("strain");
    let fitted: Vec<f64> = strains
        .iter()
        .copied()
        .filter(|c| (0.1..=0.4).contains(c))
        .collect();
    assert!(range[0] >= 0.1 && range[0] < 0.11, "{range:?}");
    assert!(
        range[1] <= *strains.last().unwrap() + 1e-9 && range[1] > 0.14,
        "{range:?}"
    );
    assert_eq!(fitted.len(), number(&s, "fit_points") as usize);
    assert_eq!(s["format_version"], 3);
    assert!(
        run.stderr.lines().any(|l| l
            .starts_with("warning: granule B2: sigma_est was fitted over strain")
            && l.contains("not 0.1 to 0.4")
            // Strains to four decimals, not the 17 digits of a sample's.
            && !l.split(|c: char| !c.is_ascii_digit()).any(|d| d.len() > 4)),
        "{}",
        run.stderr
    );

    let svg = std::fs::read_to_string(dir.join("force_displacement.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") || svg.starts_with("<?xml"),
        "{}",
        &svg[..40]
    );
    assert!(svg.contains("platen approach x, mm"), "axis label");
    assert!(svg.trim_end().ends_with("</svg>"));

    // The final state cut through the centre: hexes filled, the octant
    // mirrored (its cut hexes in all four quarters), the strain named.
    let section = std::fs::read_to_string(dir.join("section.svg")).unwrap();
    common::parse_xml(&section);
    let polygons = section.matches("<polygon").count();
    assert!(
        polygons >= 4 && polygons.is_multiple_of(4),
        "{polygons} cut hexes"
    );
    // The four quarters lie about the centre: the cut's extent is
    // symmetric in x about the picture's middle and in z about the middle
    // between the platens (the first two lines drawn).
    let numbers = |text: &str| -> Vec<f64> {
        text.split([' ', ','])
            .filter_map(|t| t.parse().ok())
            .collect()
    };
    let (mut xs, mut zs) = (Vec::new(), Vec::new());
    for line in section.lines().filter(|l| l.starts_with("<polygon")) {
        let points = line
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        for pair in numbers(points).chunks(2) {
            xs.push(pair[0]);
            zs.push(pair[1]);
        }
    }
    let extent = |v: &[f64]| {
        v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            })
    };
    let attr = |tag: &str, name: &str| -> f64 {
        tag.split(&format!("{name}=\""))
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let lines: Vec<&str> = section.split("<line").skip(1).take(2).collect();
    let ((x_lo, x_hi), (z_lo, z_hi)) = (extent(&xs), extent(&zs));
    let x_mid = 0.5 * (attr(lines[0], "x1") + attr(lines[0], "x2"));
    let z_mid = 0.5 * (attr(lines[0], "y1") + attr(lines[1], "y1"));
    assert!(
        (x_lo + x_hi - 2.0 * x_mid).abs() < 1.0,
        "x {x_lo}..{x_hi} about {x_mid}"
    );
    assert!(
        (z_lo + z_hi - 2.0 * z_mid).abs() < 1.0,
        "z {z_lo}..{z_hi} about {z_mid}"
    );
    assert!(x_hi - x_lo > 100.0 && z_hi - z_lo > 100.0);
    // The same cut coloured by the local relative density η0/J.
    let density = std::fs::read_to_string(dir.join("section_density.svg")).unwrap();
    common::parse_xml(&density);
    assert_eq!(density.matches("<polygon").count(), polygons);
    assert!(density.contains("at 15.0 % strain: local relative density η0/J"));
    assert!(
        section.contains("Granule B2 (4x1 octant) at 15.0 % strain"),
        "title"
    );

    // The report: the note as a warning, σ_est in kPa to four digits, both
    // plots captioned, the pictures, a meaning for every summary field and
    // the CSV's columns explained in its order.
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let note = granbed_cli::html::html_escape(s["notes"][0].as_str().unwrap());
    assert!(
        html.contains(&format!("<li>{note}</li>")),
        "no warning {note}"
    );
    let sigma_kpa = granbed_cli::numbers::significant(number(&s, "sigma_est_pa") * 1e-3, 4);
    assert!(
        html.contains(&format!(
            "apparent yield stress)</td><td class=\"value\">{sigma_kpa}</td>"
        )),
        "σ_est {sigma_kpa} kPa not in the key results"
    );
    assert_eq!(html.matches("<p class=\"caption\">").count(), 2);
    assert_eq!(html.matches("<svg").count(), 2);
    for picture in ["section.svg", "section_density.svg"] {
        assert!(
            html.contains(&format!("<img src=\"{picture}\"")),
            "{picture}"
        );
    }
    let energy = std::fs::read_to_string(dir.join("energy_strain.svg")).unwrap();
    assert!(energy.contains("\nplastic dissipation\n") && energy.contains("energy, "));
    let table = &html[html.find("<h2>Summary</h2>").unwrap()..html.find("<h2>Columns").unwrap()];
    assert!(
        !table.contains("<td></td></tr>"),
        "a summary field without a meaning"
    );
    assert!(table.contains("<td>quasi_static.passed</td>") && !table.contains("format_version"));
    let mut at = html.find("<h3>force_displacement.csv</h3>").unwrap();
    for column in t.header.split(',') {
        let cell = format!("<tr><td class=\"value\">{column}</td>");
        at += html[at..]
            .find(&cell)
            .unwrap_or_else(|| panic!("glossary lacks {column}"));
    }
}

/// The summary's numbers follow from the CSV it came with: the slope re-fitted
/// here from the written (round-trip exact) rows, σ_est = 4/(πd)·slope, and
/// the extremes and ledger ratios of the rows. The run goes to the default
/// 40 %, whose sample lies a step past 0.4 and is fitted too (the fit takes
/// the samples nominally at 10 % to 40 %: the bounds widened by half the
/// 0.005 output interval).
#[test]
fn summary_is_consistent_with_the_csv() {
    let dir = out_dir("consistent");
    granule_ok(&dir, &["--quiet", "--type", "C2", "--mesh", "4x1"]);
    let t = Table::read(&dir.join("force_displacement.csv"));
    let s = summary(&dir);
    let d = number(&s, "diameter_m");
    assert_eq!(d, 1.0e-3);

    let (x, f) = (t.num("displacement_m"), t.num("force_n"));
    let pts: Vec<(f64, f64)> = x
        .iter()
        .zip(&f)
        .filter(|(x, _)| (0.0975..=0.4025).contains(&(**x / d)))
        .map(|(x, f)| (*x, *f))
        .collect();
    let n = pts.len() as f64;
    let last = *t.num("strain").last().unwrap();
    assert!(
        last > 0.4 && last < 0.4001,
        "the run ends a step past 0.4: {last}"
    );
    let range = &s["sigma_est_strain_range"];
    assert_eq!(range[1].as_f64(), Some(last), "the 40 % sample is fitted");
    assert!(s["notes"].as_array().unwrap().is_empty(), "{s}");
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    // Same data, same two-pass formula: only summation order could differ.
    assert_eq!(number(&s, "fit_points"), n);
    assert_eq!(n, 61.0, "samples at strain 0.1, 0.105, …, 0.4");
    assert_close("slope", number(&s, "slope_n_per_m"), slope, 1e-12, 0.0);
    assert_close(
        "sigma_est",
        number(&s, "sigma_est_pa"),
        4.0 / (core::f64::consts::PI * d) * slope,
        1e-12,
        0.0,
    );

    let last = t.cells.len() - 1;
    let col = |name: &str| t.num(name);
    assert_eq!(number(&s, "samples"), t.cells.len() as f64);
    assert_eq!(number(&s, "final_strain"), col("strain")[last]);
    assert_eq!(number(&s, "steps"), col("steps")[last]);
    assert_eq!(
        number(&s, "max_force_n"),
        f.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    );
    assert_eq!(
        number(&s, "min_jacobian"),
        col("min_jacobian")
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    );
    assert_eq!(number(&s, "dt_s"), col("dt_s")[0]);
    let contact = col("contact_work_j")[last];
    let residual = col("gravity_work_j")[last] + contact
        - (col("kinetic_j")[last] + col("internal_work_j")[last] + col("damping_j")[last]);
    assert_close(
        "energy_residual_rel",
        number(&s, "energy_residual_rel"),
        residual / contact,
        0.0,
        1e-15,
    );
    assert_close(
        "damping_rel",
        number(&s, "damping_rel"),
        col("damping_j")[last] / contact,
        1e-15,
        0.0,
    );
    let hexes = number(&s, "mesh_hexes");
    assert_eq!(number(&s, "element_steps"), number(&s, "steps") * hexes);
    // σ_y,eff0 of C2: √a2(0.8)·100 kPa = 79.06 kPa (physics.md §0 table).
    assert_close(
        "sigma_eff0",
        number(&s, "sigma_eff0_pa"),
        79.0569e3,
        1e-5,
        0.0,
    );
}

/// The energy ledger balances to round-off (EnergyLedger::residual: every
/// work term uses the same midpoint displacement, so central differences
/// balance exactly; 1e-6 leaves nine orders of magnitude for round-off over
/// ~10⁴ steps), and hourglass modes store little of the internal work on the
/// standard mesh. On 4x1 they store about 5 % (0.051 at 15 % strain, 0.054
/// at 40 %), so this check uses 8x2 (about 2 % from 10 % strain on).
#[test]
fn energy_balances_and_hourglass_is_small() {
    let dir = out_dir("energy");
    granule_ok(&dir, &["--quiet", "--mesh", "8x2", "--strain", "0.12"]);
    let s = summary(&dir);
    let residual = number(&s, "energy_residual_rel");
    assert!(residual.abs() < 1e-6, "energy residual {residual:e}");
    let hourglass = number(&s, "hourglass_energy_rel");
    assert!((0.0..0.05).contains(&hourglass), "hourglass {hourglass}");
    let gap = number(&s, "return_map_gap_rel");
    assert!(gap.abs() < 0.05, "return-map gap {gap}");

    let dir = out_dir("energy-4x1");
    granule_ok(&dir, &["--quiet", "--mesh", "4x1", "--strain", "0.12"]);
    let residual = number(&summary(&dir), "energy_residual_rel");
    assert!(residual.abs() < 1e-6, "4x1 energy residual {residual:e}");
}

#[test]
fn platens_carry_equal_forces() {
    // Octant: the lower platen is the mirror image of the upper one, so
    // the two columns are equal by construction — this checks only that the
    // CSV reports the mirrored force; the physics check is the full
    // granule's below (§5.6 oracle 6).
    let dir = out_dir("octant");
    granule_ok(&dir, &["--quiet", "--mesh", "4x1", "--strain", "0.1"]);
    let t = Table::read(&dir.join("force_displacement.csv"));
    assert_eq!(t.num("force_upper_n"), t.num("force_lower_n"));

    // Full granule: both platens are simulated; after the contact has
    // settled (strain > 0.05) their forces agree within 1 %.
    let dir = out_dir("full");
    granule_ok(
        &dir,
        &[
            "--quiet",
            "--mesh",
            "4x1",
            "--symmetry",
            "full",
            "--strain",
            "0.1",
        ],
    );
    let t = Table::read(&dir.join("force_displacement.csv"));
    let (strain, up, low) = (
        t.num("strain"),
        t.num("force_upper_n"),
        t.num("force_lower_n"),
    );
    let late: Vec<usize> = (0..strain.len()).filter(|&i| strain[i] > 0.05).collect();
    assert!(late.len() >= 9, "{} samples after strain 0.05", late.len());
    let mean = |v: &[f64]| late.iter().map(|&i| v[i]).sum::<f64>() / late.len() as f64;
    assert_close("mean lower force", mean(&low), mean(&up), 0.01, 0.0);
    for &i in &late {
        assert_close("lower force", low[i], up[i], 0.01, 0.0);
    }
    assert_eq!(summary(&dir)["symmetry"], "full");
}

#[test]
fn bad_input_names_the_flag() {
    let dir = out_dir("bad");
    let out = dir.to_str().unwrap();
    let cases: [(&[&str], &str); 22] = [
        (&["--strain", "0"], "--strain"),
        // Numbers a double would misread, and a unit: refused by the
        // number flags' parser with the flag named by clap.
        (
            &["--yield-stress-pa", "1e400"],
            "'1e400' for '--yield-stress-pa <PA>': beyond the largest double",
        ),
        (
            &["--youngs-modulus-pa", "1e-400"],
            "'1e-400' for '--youngs-modulus-pa <PA>': below the smallest double",
        ),
        (
            &["--diameter-mm", "1mm"],
            "'1mm' for '--diameter-mm <MM>': not a number: write the number alone (`1`)",
        ),
        (
            &["--diameter-mm", "0"],
            "`--diameter-mm 0` is out of range (allowed: 0.001 <= d <= 1000 mm)",
        ),
        (&["--diameter-mm", "1e300"], "`--diameter-mm 1e300`"),
        (&["--strain", "0.95"], "--strain"),
        (&["--speed-mm-s", "-1"], "--speed-mm-s"),
        (
            &["--speed-mm-s", "1e-9"],
            "`--speed-mm-s 1e-9` rejected (allowed: 0.1 <= speed <= 10000 mm/s",
        ),
        (
            &["--output-strain", "1e-300"],
            "`--output-strain 1e-300` rejected (allowed: 1e-6 <= interval",
        ),
        // Each in range, together a wave speed 3·10⁵ times B2's: 10¹⁰
        // steps (elastic: σy ≥ 1e-6 E would be 1 MPa).
        (
            &[
                "--youngs-modulus-pa",
                "1e12",
                "--true-density-kg-m3",
                "1e-2",
                "--yield-stress-pa",
                "inf",
            ],
            "steps (a stable time step of",
        ),
        (&["--gravity"], "--gravity"),
        // σy's bound follows from E: the message says which E and bound.
        (
            &["--youngs-modulus-pa", "1e11"],
            "`--yield-stress-pa` (preset B2 value 30000) rejected (with youngs_modulus_pa = \
             1e11, i.e. at least 100000 Pa",
        ),
        (&["--mesh", "3x1"], "--mesh"),
        (&["--damping-ratio", "3"], "--damping-ratio"),
        (&["--mass-scaling", "0.5"], "--mass-scaling 0.5"),
        (&["--mass-scaling", "nan"], "--mass-scaling NaN"),
        (
            &["--rate-check", "--strain", "0.02"],
            "`--rate-check` needs `--strain` above 0.02",
        ),
        (&["--types", "A1,X9"], "--types"),
        (&["--types", "all,A1"], "`all`: write `all` alone"),
        (
            &["--types", "A2,C2", "--yield-stress-pa", "50000"],
            "--yield-stress-pa applies to every listed type: A2 and C2",
        ),
        (&["--type", "A1", "--types", "B2"], "--types"),
    ];
    for (args, flag) in cases {
        let mut argv = vec!["granule", "--out", out];
        argv.extend_from_slice(args);
        let run = cli(&argv);
        assert_eq!(run.code, 2, "{args:?}: status; stderr:\n{}", run.stderr);
        assert!(
            run.stderr.contains(flag),
            "{args:?}: {flag} not named in:\n{}",
            run.stderr
        );
    }
    // Validation happens before anything is written.
    assert!(!dir.exists(), "a rejected run created {}", dir.display());
    // The gravity message says what would make it valid.
    let run = cli(&["granule", "--out", out, "--gravity"]);
    assert!(run.stderr.contains("--symmetry full"), "{}", run.stderr);
    // A material override is rejected by the flag name too.
    let run = cli(&["granule", "--out", out, "--friction", "20"]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("--friction 20"), "{}", run.stderr);
    let missing = cli(&["granule"]);
    assert_eq!(missing.code, 2);
    assert!(missing.stderr.contains("--out"), "{}", missing.stderr);
}

/// `--diameter-mm`: without gravity the equations of motion are
/// unchanged when lengths and time are scaled together (velocities,
/// strains and stresses stay), and the element time step scales with the
/// mesh. So a granule of twice the diameter at the same platen speed takes
/// the same steps to the same strains, with the same σ_est and four times
/// the force, up to round-off (2·10⁻¹⁰ measured; 10⁻⁸ allowed). A radius
/// not passed to the mesh, or a step not scaled with it, fails this.
#[test]
fn a_granule_twice_the_size_is_the_same_experiment_scaled() {
    let (small, large) = (out_dir("d1"), out_dir("d2"));
    granule_ok(&small, &QUICK);
    let mut args = QUICK.to_vec();
    args.extend_from_slice(&["--diameter-mm", "2"]);
    granule_ok(&large, &args);
    let (a, b) = (summary(&small), summary(&large));
    assert_eq!(number(&a, "diameter_m"), 1.0e-3);
    assert_eq!(number(&b, "diameter_m"), 2.0e-3);
    assert_eq!(a["steps"], b["steps"]);
    assert_close(
        "sigma_est_pa",
        number(&b, "sigma_est_pa"),
        number(&a, "sigma_est_pa"),
        1e-8,
        0.0,
    );
    let (ta, tb) = (
        Table::read(&small.join("force_displacement.csv")),
        Table::read(&large.join("force_displacement.csv")),
    );
    let (fa, fb) = (ta.num("force_n"), tb.num("force_n"));
    let (sa, sb) = (ta.num("strain"), tb.num("strain"));
    assert_eq!(fa.len(), fb.len());
    let peak = fa.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    assert!(peak > 0.0);
    for i in 0..fa.len() {
        assert!(
            (sb[i] - sa[i]).abs() < 1e-9,
            "row {i}: strain {} vs {}",
            sb[i],
            sa[i]
        );
        assert!(
            (fb[i] - 4.0 * fa[i]).abs() <= 1e-8 * 4.0 * peak,
            "row {i}: force {} vs 4 × {}",
            fb[i],
            fa[i]
        );
    }
}

/// `--mass-scaling F`: √F fewer steps, the same curve within the rate
/// check's limit, and the quasi-static certificate in the summary — passed
/// for a coarse B2 at ×10 with the rate check run, measured force imbalance
/// with the full granule, and failed (with a warning on stderr) for a
/// granule so heavy that its inertia carries the load.
#[test]
fn mass_scaling_keeps_the_curve_and_the_certificate_says_so() {
    let quick = ["--quiet", "--mesh", "4x1", "--strain", "0.2"];
    let plain = out_dir("mass_x1");
    granule_ok(&plain, &quick);
    let scaled = out_dir("mass_x10");
    let run = granule_ok(
        &scaled,
        &[&quick[..], &["--mass-scaling", "10", "--rate-check"]].concat(),
    );
    assert!(!run.stderr.contains("NOT quasi-static"), "{}", run.stderr);
    let (s1, s10) = (summary(&plain), summary(&scaled));
    assert_eq!(s1["mass_scaling"], 1.0);
    assert_eq!(s10["mass_scaling"], 10.0);
    let steps = |s: &Value| number(s, "steps");
    assert_close(
        "step ratio",
        steps(&s1) / steps(&s10),
        10f64.sqrt(),
        0.03,
        0.0,
    );
    for s in [&s1, &s10] {
        let q = &s["quasi_static"];
        assert_eq!(q["passed"], true, "{q}");
        assert!(number(q, "max_kinetic_to_internal") < 0.01, "{q}");
        // Octant: the lower platen mirrors the upper one, nothing to measure.
        assert!(q["force_imbalance_rel"].is_null(), "{q}");
    }
    assert!(s1["quasi_static"]["rate_change_rel"].is_null());
    let change = number(&s10["quasi_static"], "rate_change_rel");
    assert!(change > 0.0 && change < 0.05, "rate change {change}");
    // The curves of x1 and x10 agree within the rate check's limit over
    // the second half.
    let force = |d: &Path| Table::read(&d.join("force_displacement.csv")).num("force_n");
    let (f1, f10) = (force(&plain), force(&scaled));
    assert_eq!(f1.len(), f10.len());
    let tail = f1.len() / 2..f1.len();
    let dist: f64 = tail
        .clone()
        .map(|i| (f10[i] - f1[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    let norm: f64 = tail.map(|i| f1[i] * f1[i]).sum::<f64>().sqrt();
    assert!(dist / norm < 0.05, "x1 vs x10 curves: {}", dist / norm);

    // The full granule measures the platen force imbalance.
    let full = out_dir("mass_full");
    granule_ok(
        &full,
        &[&quick[..], &["--symmetry", "full", "--mass-scaling", "10"]].concat(),
    );
    let q = &summary(&full)["quasi_static"];
    assert!(number(q, "force_imbalance_rel") < 0.05, "{q}");
    assert_eq!(q["passed"], true, "{q}");

    // At x1e6 the granule is a heavy ball hitting the platens: the
    // certificate fails and stderr says so; the run itself succeeds.
    let heavy = out_dir("mass_heavy");
    let run = granule_ok(&heavy, &[&quick[..], &["--mass-scaling", "1e6"]].concat());
    let q = &summary(&heavy)["quasi_static"];
    assert_eq!(q["passed"], false, "{q}");
    assert!(number(q, "max_kinetic_to_internal") > 0.01, "{q}");
    assert!(
        run.stderr
            .contains("NOT quasi-static with mass scaling 1000000"),
        "{}",
        run.stderr
    );
}

/// `--types` runs each type into its own directory and tabulates them; the
/// stronger, denser granule has the larger σ_est. Thread count does not
/// change any result.
#[test]
fn types_are_tabulated_and_independent_of_threads() {
    let dir = out_dir("types");
    let common = [
        "--quiet", "--mesh", "4x1", "--strain", "0.2", "--types", "A1,C3",
    ];
    let mut args = common.to_vec();
    args.extend(["-j", "2"]);
    granule_ok(&dir, &args);
    let t = Table::read(&dir.join("types.csv"));
    assert_eq!(
        t.header,
        "type,sigma_y_pa,eta0,sigma_eff0_pa,sigma_est_pa,slope_n_per_m,fit_r_squared,\
         quasi_static_passed,steps,wall_time_s,energy_residual_rel,return_map_gap_rel"
    );
    assert_eq!(t.text("type"), ["A1", "C3"]);
    let sigma = t.num("sigma_est_pa");
    assert!(
        sigma[1] > sigma[0],
        "sigma_est A1 {} vs C3 {}",
        sigma[0],
        sigma[1]
    );
    assert_eq!(t.num("eta0"), [0.6, 1.0]);
    for (i, ty) in ["A1", "C3"].into_iter().enumerate() {
        let s = summary(&dir.join(ty));
        assert_eq!(s["granule_type"], ty);
        assert_eq!(
            number(&s, "sigma_est_pa"),
            sigma[i],
            "types.csv row of {ty}"
        );
        assert_eq!(number(&s, "fit_r_squared"), t.num("fit_r_squared")[i]);
        let passed = s["quasi_static"]["passed"].as_bool().unwrap();
        assert_eq!(t.num("quasi_static_passed")[i], f64::from(u8::from(passed)));
    }
    let svg = std::fs::read_to_string(dir.join("force_displacement_types.svg")).unwrap();
    assert!(svg.starts_with("<svg"));
    // The series' page links each type's report; both runs ended at 0.2,
    // before σ_est's window closed, so both σ_est are marked.
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    for ty in ["A1", "C3"] {
        assert!(html.contains(&format!("<a href=\"{ty}/report.html\">{ty}</a>")));
        assert!(dir.join(ty).join("report.html").is_file());
    }
    assert_eq!(html.matches(" ✗</td>").count(), 2, "{html}");
    assert_eq!(html.matches("<svg").count(), 1);

    let serial = out_dir("types-serial");
    let mut args = common.to_vec();
    args.extend(["-j", "1"]);
    granule_ok(&serial, &args);
    for ty in ["A1", "C3"] {
        let a = std::fs::read(dir.join(ty).join("force_displacement.csv")).unwrap();
        let b = std::fs::read(serial.join(ty).join("force_displacement.csv")).unwrap();
        assert!(a == b, "{ty}: -j 1 and -j 2 differ");
    }
}

#[test]
fn identical_runs_write_identical_files() {
    let (a, b) = (out_dir("det-a"), out_dir("det-b"));
    granule_ok(&a, &QUICK);
    granule_ok(&b, &QUICK);
    for file in ["force_displacement.csv", "force_displacement.svg"] {
        let (x, y) = (
            std::fs::read(a.join(file)).unwrap(),
            std::fs::read(b.join(file)).unwrap(),
        );
        assert!(x == y, "{file} differs between identical runs");
    }
}

/// Runs `granbed-cli granule --quiet --out DIR --mesh 4x1 ARGS` and
/// asserts that the kernel stopped it (status 1).
fn granule_fails(dir: &Path, args: &[&str]) -> Run {
    let mut argv = vec![
        "granule",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--mesh",
        "4x1",
    ];
    argv.extend_from_slice(args);
    let run = cli(&argv);
    assert_eq!(run.code, 1, "{}", run.stderr);
    run
}

/// Without hourglass control (κ = 0) the coarse granule folds (at 25 %
/// strain): the time step cannot be estimated on a folded element, and
/// the error names the element, its Jacobian ratio, the step and the
/// strain, on stderr and in the summary.
#[test]
fn a_folded_element_is_named() {
    let dir = out_dir("folded");
    let run = granule_fails(&dir, &["--hourglass-kappa", "0", "--strain", "0.3"]);
    let s = summary(&dir);
    let error = s["error"].as_str().expect("summary has the error");
    for part in [
        "step ",
        "(strain 0.",
        "folded or inverted",
        "Jacobian ratio -",
    ] {
        assert!(error.contains(part), "{part:?} missing from {error}");
        assert!(
            run.stderr.contains(part),
            "{part:?} missing from {}",
            run.stderr
        );
    }
    let element: usize = error
        .split("element ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no element number in {error}"));
    assert!(element < 20, "the octant 4x1 mesh has 20 hexes: {element}");
}

/// Regression guard for the failure path: without hourglass control the
/// coarse granule folds at about 25 % strain. The rows so far, the summary
/// with its error and the plot are kept, and the message names type,
/// step, strain and element. (A platen at 10 m/s inverted an element
/// within a few dozen steps while a step could carry the platens 5 % of
/// the diameter; since steps are capped at 0.1 % it runs to the end and
/// fails the quasi-static certificate instead.)
#[test]
fn kernel_failure_keeps_partial_results() {
    let dir = out_dir("failure");
    // A finished run first, whose pictures the failed run must not keep.
    granule_ok(&dir, &QUICK);
    assert!(dir.join("section.svg").is_file() && dir.join("section_density.svg").is_file());
    let run = granule_fails(&dir, &["--hourglass-kappa", "0", "--strain", "0.3"]);
    for part in ["granule B2", "step ", "strain ", "element ", "summary.json"] {
        assert!(
            run.stderr.contains(part),
            "{part:?} missing from:\n{}",
            run.stderr
        );
    }
    let t = Table::read(&dir.join("force_displacement.csv"));
    assert!(t.cells.len() >= 2, "rows before the failure");
    let s = summary(&dir);
    let error = s["error"].as_str().expect("summary has the error");
    assert!(error.contains("element"), "{error}");
    assert_eq!(number(&s, "samples"), t.cells.len() as f64);
    assert!(dir.join("force_displacement.svg").exists());
    // A failed step's state is no picture to show, and an earlier run's
    // picture in the directory is removed (the test writes one first).
    assert!(!dir.join("section.svg").exists());
    assert!(!dir.join("section_density.svg").exists());
    // The report says the run stopped and shows no picture.
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(html.contains("<p><strong>The run stopped early:</strong>"));
    assert!(!html.contains("<img"));
}

/// A coarse output interval keeps the unloaded state out of σ_est, and the
/// notes say what the fit covered: sampled every 0.2 the fit starts at the
/// 0.2 sample (half an interval at the low end would have reached down to
/// strain 0 and fitted the unloaded state, 34 % low with samples every
/// 0.4); every 0.4 there is one sample in 0.1–0.4 and no σ_est.
#[test]
fn a_coarse_output_interval_keeps_the_unloaded_state_out_of_sigma_est() {
    let dir = out_dir("coarse_interval");
    let run = granule_ok(&dir, &["--mesh", "4x1", "--output-strain", "0.2"]);
    let s = summary(&dir);
    let range = &s["sigma_est_strain_range"];
    let first = range[0].as_f64().unwrap();
    assert!((0.2..0.2001).contains(&first), "{range}");
    assert_eq!(number(&s, "fit_points"), 2.0);
    let note = s["notes"][0].as_str().unwrap();
    assert!(
        note.contains("not 0.1 to 0.4: the output interval 0.2 places no sample near 0.1"),
        "{note}"
    );
    assert!(run.stderr.contains(note), "{}", run.stderr);
    let dir = out_dir("coarse_interval_04");
    granule_ok(&dir, &["--mesh", "4x1", "--output-strain", "0.4"]);
    let s = summary(&dir);
    assert_eq!(s["sigma_est_pa"], Value::Null, "{s}");
    let note = s["notes"][0].as_str().unwrap();
    assert!(
        note.contains("the output interval 0.4 places fewer there"),
        "{note}"
    );
}

/// The summary spells the element as its flag does (`fbar`; format 3).
#[test]
fn the_summary_names_the_element_as_the_flag_does() {
    let dir = out_dir("fbar_name");
    granule_ok(
        &dir,
        &["--mesh", "4x1", "--element", "fbar", "--strain", "0.02"],
    );
    let s = summary(&dir);
    assert_eq!(s["element"], "fbar", "{s}");
    assert_eq!(s["format_version"], 3);
}
