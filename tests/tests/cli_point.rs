//! `granbed-cli point`: the material-point explorer, driven end to end.
//!
//! Each test runs the command line through `granbed_cli::run` and
//! `granbed_cli::error::report` with in-memory streams: exactly what the
//! binary's `main` does with the process's streams (cli/src/main.rs is those
//! two calls), so the exit status, stdout and stderr seen here are the
//! binary's. The binary itself cannot be spawned from this package: Cargo
//! sets `CARGO_BIN_EXE_granbed-cli` only for integration tests of the CLI
//! package, and does not build a dependency's binaries.

mod common;

use clap::CommandFactory as _;
use common::{Run, Table, assert_close, cli};
use granbed_kernel::material::GranuleType;

/// Runs `granbed-cli point ARGS` and asserts success.
fn point_ok(args: &[&str]) -> Run {
    let argv: Vec<&str> = core::iter::once("point")
        .chain(args.iter().copied())
        .collect();
    let run = cli(&argv);
    assert_eq!(run.code, 0, "point {args:?} failed:\n{}", run.stderr);
    run
}

/// The header `point` must write, in this order.
const HEADER: &str = "step,strain,f_xx,f_yy,f_zz,f_xy,j,tau_xx,tau_yy,tau_zz,tau_yz,tau_xz,\
                      tau_xy,sigma_xx,sigma_yy,sigma_zz,sigma_yz,sigma_xz,sigma_xy,\
                      pressure_pa,von_mises_pa,eta,plastic,iterations";

/// Hydrostatic compression stays on the yield surface's pressure cap: with
/// dev τ = 0, φ = 0 gives p = (σy/3)·√(2 a2(η)/a1(η)). Checked on every
/// plastic row against the row's own η.
#[test]
fn hydrostatic_a1_plastic_rows_sit_on_the_pressure_cap() {
    let preset = GranuleType::A1.params();
    assert_eq!((preset.eta0, preset.yield_stress_pa), (0.6, 10.0e3));
    let run = point_ok(&[
        "--type",
        "A1",
        "--path",
        "hydrostatic",
        "--strain",
        "0.35",
        "--steps",
        "2000",
    ]);
    assert_eq!(run.stdout.lines().next(), Some(HEADER));
    let t = Table::parse(&run.stdout);
    let rows = t.rows();
    assert_eq!(rows.len(), 2001, "rows for steps 0..=2000");
    let last = rows.last().unwrap();
    assert_eq!(
        last[t.col("strain")],
        0.35,
        "last row reaches --strain exactly"
    );
    assert_eq!(last[t.col("step")], 2000.0);

    let (sy, cp, ec) = (preset.yield_stress_pa, preset.cp, preset.eta_c);
    let mut plastic = 0;
    for row in &rows {
        if row[t.col("plastic")] == 0.0 {
            continue;
        }
        plastic += 1;
        let eta = row[t.col("eta")];
        let a1 = cp * (1.0 - eta * eta);
        let a2 = (eta * eta - ec * ec) / (1.0 - ec * ec);
        let expected = sy / 3.0 * (2.0 * a2 / a1).sqrt();
        // The return map converges to |φ|/scale ~ 1e-12 and the CSV round
        // trip is exact, so p matches to well below 1e-10 relative.
        let step = row[t.col("step")];
        assert_close(
            &format!("pressure at step {step} (eta {eta})"),
            row[t.col("pressure_pa")],
            expected,
            1.0e-10,
            0.0,
        );
        // J and η agree with the path definition J = 1 − strain, η = η0/J
        // (only rounding of the cube root and the product F·F·F, ~1e-15).
        let j = row[t.col("j")];
        assert_close("j", j, 1.0 - row[t.col("strain")], 1.0e-14, 0.0);
        assert_close("eta", eta, preset.eta0 / j, 1.0e-14, 0.0);
    }
    assert!(plastic >= 1500, "only {plastic} plastic rows");
    assert!(
        run.stderr.contains(&format!("{plastic} plastic")),
        "summary names the plastic steps: {}",
        run.stderr
    );
}

/// Bad input is a usage error (status 2) whose message names the flag and
/// what is allowed, and nothing is written to stdout.
#[test]
fn bad_input_names_the_flag_and_the_range() {
    let cases: [(&[&str], &[&str]); 8] = [
        (
            &["--path", "hydrostatic", "--eta0", "0.1"],
            &["--eta0", "eta_c < eta0 <= 1", "eta_c = 0.2"],
        ),
        (
            &["--path", "hydrostatic", "--poisson-ratio", "0.6"],
            &["--poisson-ratio", "-1 < nu < 0.5"],
        ),
        (
            &["--path", "hydrostatic", "--strain", "1.5"],
            &["--strain", "-10 < strain < 1", "hydrostatic"],
        ),
        (
            &["--path", "shear", "--strain", "-10"],
            &["--strain", "-10 < strain < 10"],
        ),
        (
            &["--path", "hydrostatic", "--type", "Z9"],
            &["--type", "Z9", "A1, A2"],
        ),
        (
            &["--path", "hydrostatic", "--steps", "0"],
            &["--steps", "1..=10000000"],
        ),
        (
            &["--path", "hydrostatic", "--steps", "1e3"],
            &["--steps", "not a whole number", "1..=10000000"],
        ),
        (
            // η0 from the preset becomes invalid through another flag.
            &["--path", "shear", "--type", "A1", "--eta-c", "0.6"],
            &["--eta0", "preset A1", "eta_c = 0.6"],
        ),
    ];
    for (args, needles) in cases {
        let argv: Vec<&str> = core::iter::once("point")
            .chain(args.iter().copied())
            .collect();
        let run = cli(&argv);
        assert_eq!(run.code, 2, "{args:?}: status; stderr:\n{}", run.stderr);
        assert!(
            run.stderr.starts_with("error: "),
            "{args:?}: {}",
            run.stderr
        );
        for needle in needles {
            assert!(
                run.stderr.contains(needle),
                "{args:?}: stderr lacks {needle:?}:\n{}",
                run.stderr
            );
        }
        assert!(run.stdout.is_empty(), "{args:?}: wrote {:?}", run.stdout);
    }
    let missing = cli(&["point"]);
    assert_eq!(missing.code, 2);
    assert!(missing.stderr.contains("--path"), "{}", missing.stderr);
}

/// The lines of `help` that document `flag`: its own line and the indented
/// help text below it, up to the next option or heading.
fn help_block<'h>(help: &'h str, flag: &str) -> Vec<&'h str> {
    let indent = |l: &str| l.len() - l.trim_start().len();
    let mut lines = help.lines().skip_while(|l| {
        let t = l.trim_start();
        // `-h, --help`: look past a short form.
        let t = match t.split_once(", ") {
            Some((short, long)) if !short.starts_with("--") => long,
            _ => t,
        };
        !(indent(l) <= 6 && (t == flag || t.starts_with(&format!("{flag} "))))
    });
    let first = lines
        .next()
        .unwrap_or_else(|| panic!("--help lacks {flag}"));
    core::iter::once(first)
        .chain(lines.take_while(|l| l.trim().is_empty() || indent(l) >= 10))
        .collect()
}

/// `point --help` documents every option, with its unit.
#[test]
fn help_lists_every_option_with_units() {
    let run = cli(&["point", "--help"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(run.stderr.is_empty());
    let help = &run.stdout;
    let expected: [(&str, &[&str]); 15] = [
        ("--type", &["A1", "C3", "kPa", "[default: B2]"]),
        (
            "--path",
            &["hydrostatic", "uniaxial-strain", "uniaxial-stress", "shear"],
        ),
        (
            "--strain",
            &["dimensionless", "1 − J", "γ", "[default: 0.3]"],
        ),
        ("--steps", &["10000000", "[default: 1000]"]),
        ("--out", &["stdout"]),
        ("--literal-return", &["volume"]),
        ("--youngs-modulus-pa", &["Pa"]),
        ("--poisson-ratio", &["dimensionless", "0.5"]),
        ("--yield-stress-pa", &["Pa"]),
        ("--eta0", &["dimensionless", "≤ 1"]),
        ("--cp", &["dimensionless"]),
        ("--eta-c", &["dimensionless", "< 1"]),
        ("--true-density-kg-m3", &["kg/m³"]),
        ("--friction", &["dimensionless"]),
        ("--help", &["help"]),
    ];
    for (flag, needles) in expected {
        let block = help_block(help, flag).join("\n");
        for needle in needles {
            assert!(
                block.contains(needle),
                "{flag} help lacks {needle:?}:\n{block}"
            );
        }
    }
    // Nothing clap knows of is left out or undocumented.
    let cmd = granbed_cli::Cli::command();
    let point = cmd.find_subcommand("point").expect("point subcommand");
    for arg in point.get_arguments() {
        let Some(long) = arg.get_long() else { continue };
        let flag = format!("--{long}");
        assert!(
            expected.iter().any(|(f, _)| *f == flag),
            "{flag} is not covered by this test"
        );
        assert!(
            help_block(help, &flag).len() >= 2,
            "{flag} has no help text"
        );
    }
    // The output columns are explained too.
    for column in HEADER
        .split(',')
        .filter(|c| !c.contains('_') || c.ends_with("_pa"))
    {
        assert!(help.contains(column), "--help does not explain {column}");
    }
}

/// Uniaxial stress keeps the lateral faces stress free while the axial
/// stress builds up.
#[test]
fn uniaxial_stress_rows_have_no_lateral_stress() {
    let run = point_ok(&[
        "--path",
        "uniaxial-stress",
        "--strain",
        "0.3",
        "--steps",
        "300",
    ]);
    let t = Table::parse(&run.stdout);
    let rows = t.rows();
    assert_eq!(rows.len(), 301);
    // The kernel solves |τ_xx + τ_yy|/2 ≤ 1e-13·E = 1e-7 Pa; 1e-6 Pa allows
    // for the split between the two (equal by symmetry).
    for row in &rows {
        for c in ["tau_xx", "tau_yy"] {
            let v = row[t.col(c)];
            assert!(
                v.abs() <= 1.0e-6,
                "{c} = {v:e} Pa at step {}",
                row[t.col("step")]
            );
        }
    }
    let last = rows.last().unwrap();
    assert!(last[t.col("tau_zz")] < -1.0e3, "axial stress builds up");
    assert!(last[t.col("f_xx")] > 1.0, "lateral faces move out");
    assert!(rows.iter().any(|r| r[t.col("plastic")] == 1.0));
}

/// `--out FILE` writes the same bytes as stdout, and `--out -` is stdout.
#[test]
fn out_file_matches_stdout() {
    let args = [
        "--path", "shear", "--strain", "0.5", "--steps", "50", "--type", "C1",
    ];
    let to_stdout = point_ok(&args);
    let dash: Vec<&str> = args.iter().copied().chain(["--out", "-"]).collect();
    assert_eq!(point_ok(&dash).stdout, to_stdout.stdout);
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_point_shear.csv");
    let path_str = path.to_str().expect("UTF-8 temp path");
    let to_file: Vec<&str> = args.iter().copied().chain(["--out", path_str]).collect();
    let run = point_ok(&to_file);
    assert!(run.stdout.is_empty());
    let written = std::fs::read_to_string(&path).expect("output file");
    assert_eq!(written, to_stdout.stdout);
}

/// `--literal-return` reaches the kernel: without the volume fix, simple
/// shear (J = 1) gives a different stress history.
#[test]
fn literal_return_changes_shear_response() {
    let args = [
        "--path", "shear", "--strain", "1", "--steps", "100", "--type", "A1",
    ];
    let fixed = Table::parse(&point_ok(&args).stdout);
    let literal: Vec<&str> = args.iter().copied().chain(["--literal-return"]).collect();
    let literal = Table::parse(&point_ok(&literal).stdout);
    let differs = fixed
        .num("pressure_pa")
        .iter()
        .zip(literal.num("pressure_pa"))
        .any(|(a, b)| *a != b);
    assert!(differs, "--literal-return made no difference");
}

/// If the kernel fails mid-run, the rows before the failing step are kept,
/// the status is 1 and the message names the step and the strain. (One large
/// shear step is a case the return map currently cannot solve; should the
/// kernel learn to, the run must instead succeed with both rows.)
#[test]
fn kernel_failure_keeps_rows_and_names_the_step() {
    let run = cli(&[
        "point", "--path", "shear", "--strain", "9.99", "--steps", "1",
    ]);
    let t = Table::parse(&run.stdout);
    match run.code {
        0 => assert_eq!(t.cells.len(), 2),
        1 => {
            assert_eq!(t.cells.len(), 1, "row 0 is kept");
            for needle in ["error: ", "step 1 of 1", "strain 9.99", "stdout"] {
                assert!(
                    run.stderr.contains(needle),
                    "lacks {needle:?}: {}",
                    run.stderr
                );
            }
        }
        code => panic!("status {code}: {}", run.stderr),
    }
}

/// Negative values in every spelling a float takes reach the flag: clap
/// alone took `-1e-3`, `-.5` and `-inf` for short options ("unexpected
/// argument '-1'"). Shear to −γ is shear to γ mirrored: the same pressure.
#[test]
fn negative_values_in_any_spelling_reach_the_flag() {
    let pressure = |strain: &str| {
        let run = point_ok(&["--path", "shear", "--strain", strain, "--steps", "20"]);
        Table::parse(&run.stdout)
            .num("pressure_pa")
            .last()
            .copied()
            .unwrap()
    };
    assert_eq!(pressure("-1e-3"), pressure("1e-3"));
    assert_eq!(pressure("-.5"), pressure("0.5"));
    let run = cli(&[
        "point",
        "--path",
        "shear",
        "--poisson-ratio",
        "-1e-1",
        "--strain",
        "0.01",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let run = cli(&["point", "--path", "shear", "--strain", "-inf"]);
    assert_eq!(run.code, 2);
    assert!(run.stderr.contains("--strain"), "{}", run.stderr);
}

/// A path that closes the pores says where: η = η0/J reaches 1 and the
/// note names the step and strain (B2, η0 = 0.8: J = 0.8 at a hydrostatic
/// strain of 0.2, so the first step at or past it); a path that stays
/// porous has no note.
#[test]
fn a_path_past_full_density_says_where_the_pores_closed() {
    let b2_hydrostatic = |strain: &str, steps: &str| {
        point_ok(&[
            "--type",
            "B2",
            "--path",
            "hydrostatic",
            "--strain",
            strain,
            "--steps",
            steps,
        ])
    };
    let run = b2_hydrostatic("0.3", "30");
    let note = run
        .stderr
        .lines()
        .find(|l| l.starts_with("note: eta reached 1 at step "))
        .unwrap_or_else(|| panic!("no note:\n{}", run.stderr));
    // The first of the steps 0.01 apart at or past 0.2 (0.2 itself may
    // round either side of 1).
    let strain: f64 = note
        .split("(strain ")
        .nth(1)
        .and_then(|t| t.split(')').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{note}"));
    assert!((0.2..=0.21).contains(&strain), "{note}");
    let run = b2_hydrostatic("0.05", "10");
    assert!(!run.stderr.contains("eta reached 1"), "{}", run.stderr);
}

/// The closing line says the strain short and an unstressed point's
/// pressure as 0: a strain of 1e-300 was printed with 300 digits, and the
/// pressure of no stress, −tr τ/3 of zeros, as -0.
#[test]
fn the_closing_line_says_a_tiny_strain_short_and_no_pressure_as_zero() {
    let run = point_ok(&[
        "--path",
        "hydrostatic",
        "--strain",
        "1e-300",
        "--steps",
        "3",
    ]);
    let line = run
        .stderr
        .lines()
        .find(|l| l.starts_with("point: "))
        .unwrap_or_else(|| panic!("no closing line:\n{}", run.stderr));
    assert!(line.contains("to strain 1e-300:"), "{line}");
    assert!(line.contains("final pressure 0.000000e0 Pa"), "{line}");
}
