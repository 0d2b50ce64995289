//! The upper punch's withdrawal after the final strain (scene `unload`,
//! on in the published scene) on a bed of 100 coarse granules in a 5 mm
//! die pressed to 20 % (exact contact from 18 %): `unloading.csv` continues `compression.csv` with
//! the strain falling until the punch comes free, and what the bed gives
//! back obeys the physics of a dissipative cycle: the unloading curve lies
//! below the loading curve, and the work given back is the punch force's
//! integral over its withdrawal and at most the granules' elastic energy
//! at the turn. The checkpoint keeps the loading's end, so a larger
//! `--strain` continues the loading; a finished run resumed keeps its
//! withdrawal; `--unload false` ends at the final strain.

mod common;

use common::{Table, cli, fresh_dir, number, small_bed, summary};

/// The loading curve's upper-punch pressure at mean strain `c`, linear
/// between the rows of `compression.csv`.
fn loading_pressure(rows: &Table, c: f64) -> f64 {
    let (x, p) = (rows.num("mean_strain"), rows.num("upper_pressure_pa"));
    let k = x.partition_point(|&m| m < c).clamp(1, x.len() - 1);
    p[k - 1] + (p[k] - p[k - 1]) * (c - x[k - 1]) / (x[k] - x[k - 1])
}

#[test]
fn the_punch_withdraws_until_the_bed_lets_go() {
    let dir = fresh_dir("cli_bed_unloading", "bed100");
    let out = dir.to_str().unwrap();
    // Exact contact from 0.18: the loading's end searches every sweep,
    // and the withdrawal returns to the held constraints below 0.18.
    let mut argv = vec![
        "bed",
        "--quiet",
        "--exact-contact-from-strain",
        "0.18",
        "--out",
        out,
    ];
    argv.extend_from_slice(&small_bed("100", "0.2"));
    let run = cli(&argv);
    assert_eq!(run.code, 0, "bed failed:\n{}", run.stderr);
    let s = summary(&dir);
    let u = &s["unloading"];
    let loading = Table::read(&dir.join("compression.csv"));
    let unloading = Table::read(&dir.join("unloading.csv"));
    assert_eq!(unloading.header, loading.header);
    let from = number(u, "from_strain");
    assert_eq!(from, *loading.num("strain").last().unwrap());
    assert_eq!(number(u, "rows"), unloading.cells.len() as f64);

    // The strain falls row by row from the turn; the punch lets go within
    // the withdrawal allowed: the last row's force is the first below 1 %
    // of the loading's largest.
    let strain = unloading.num("strain");
    assert!(strain[0] < from && strain.windows(2).all(|w| w[1] < w[0]));
    assert!(from - strain.last().unwrap() < 0.15 + 1e-9);
    let largest = loading
        .num("upper_force_n")
        .iter()
        .fold(0.0, |m: f64, &f| m.max(f));
    let force = unloading.num("upper_force_n");
    let (last, before) = force.split_last().unwrap();
    assert!(*last < 0.01 * largest && before.iter().all(|&f| f >= 0.01 * largest));
    // Lift-off lies between the last row's mean strain and the one before
    // (the turn for a first row).
    let mean = unloading.num("mean_strain");
    let lift = number(u, "lift_off_strain");
    let n = mean.len();
    let above = if n > 1 { mean[n - 2] } else { from };
    assert!(lift >= mean[n - 1] && lift <= above, "lift-off {lift}");
    let recovery = number(u, "elastic_recovery");
    assert!((recovery - (from - lift) / (1.0 - from)).abs() < 1e-15);
    assert!(recovery > 0.0 && recovery < 0.1, "recovery {recovery}");

    // Back below the exact-contact strain the withdrawal holds its
    // contacts between searches again: the overlaps stay below 1 % of the
    // element, as the loading's do (issue #9's bound).
    assert!(
        *strain.last().unwrap() < 0.18 - 0.01,
        "the switch was not reached"
    );
    let element = number(&s, "max_penetration_m") / number(&s, "max_penetration_rel_element");
    for (c, d) in strain.iter().zip(unloading.num("penetration_m")) {
        assert!(
            d < 0.01 * element,
            "C = {c}: overlap {d} m of element {element} m"
        );
    }

    // Hysteresis: at every strain of the withdrawal the bed pushes the
    // punch less than it resisted it on the way in.
    for (c, p) in mean.iter().zip(unloading.num("upper_pressure_pa")) {
        let on_the_way_in = loading_pressure(&loading, *c);
        assert!(
            p < on_the_way_in,
            "C = {c}: {p} Pa out, {on_the_way_in} Pa in"
        );
    }

    // The work given back: the punch work's fall, which is the rows'
    // averaged forces times the punch's travel in each row's interval (the
    // ledger and the rows to round-off), at most the elastic energy at the
    // turn, and the net work the rest of the loading work.
    let h0 = number(&s, "initial_bed_height_m");
    let work = loading.num("punch_work_j");
    let loading_work = *work.last().unwrap();
    assert_eq!(number(u, "loading_work_j"), loading_work);
    let returned = number(u, "returned_work_j");
    let integral: f64 = force
        .iter()
        .zip(
            core::iter::once(from)
                .chain(strain.iter().copied())
                .zip(&strain),
        )
        .map(|(f, (c0, c1))| f * (c0 - c1) * h0)
        .sum();
    assert!(
        (integral / returned - 1.0).abs() < 1e-9,
        "∫F dz {integral} J, ledger {returned} J"
    );
    let elastic = number(u, "elastic_energy_at_end_j");
    assert!(
        returned > 0.0 && returned < elastic,
        "{returned} J of Ψ {elastic} J"
    );
    assert_eq!(number(u, "net_work_j"), loading_work - returned);
    assert!(number(u, "plasticity_factor") > 0.5);
    // The die wall still presses on the compact the punch let go of.
    assert!(number(u, "residual_die_wall_pressure_pa") > 0.0);
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(html.contains("in-die elastic recovery"), "no key result");

    // A finished run resumed without a step keeps its withdrawal.
    let csv = std::fs::read(dir.join("unloading.csv")).unwrap();
    let again = cli(&["bed", "--quiet", "--resume", out]);
    assert_eq!(again.code, 0, "{}", again.stderr);
    assert_eq!(summary(&dir)["unloading"], s["unloading"]);
    assert_eq!(std::fs::read(dir.join("unloading.csv")).unwrap(), csv);
    // So does one refitted (its checkpoint written again with the changed
    // scene), and the next resume after it: the same withdrawal, wall time
    // included, not a new one.
    for refit in [&["--kawakita-min-strain", "0.1"][..], &[]] {
        let mut argv = vec!["bed", "--quiet", "--resume", out];
        argv.extend_from_slice(refit);
        let again = cli(&argv);
        assert_eq!(again.code, 0, "{}", again.stderr);
        assert_eq!(summary(&dir)["unloading"], s["unloading"], "{refit:?}");
    }

    // The checkpoint holds the loading's end: a larger --strain continues
    // the loading (its rows so far unchanged), then withdraws from there.
    let further = cli(&["bed", "--quiet", "--resume", out, "--strain", "0.25"]);
    assert_eq!(further.code, 0, "{}", further.stderr);
    let longer = Table::read(&dir.join("compression.csv"));
    assert_eq!(longer.cells[..loading.cells.len()], loading.cells[..]);
    assert!(*longer.num("strain").last().unwrap() > 0.25 - 1e-9);
    let u2 = &summary(&dir)["unloading"];
    assert_eq!(
        number(u2, "from_strain"),
        *longer.num("strain").last().unwrap()
    );

    // Resumed without the withdrawal, the finished run's outputs lose it.
    let off = cli(&["bed", "--quiet", "--resume", out, "--unload", "false"]);
    assert_eq!(off.code, 0, "{}", off.stderr);
    assert!(summary(&dir)["unloading"].is_null());
    assert!(!dir.join("unloading.csv").exists());

    // Without the withdrawal: no unloading.csv, no figures.
    let plain = fresh_dir("cli_bed_unloading", "plain");
    let mut argv = vec!["bed", "--quiet", "--unload", "false", "--out"];
    argv.push(plain.to_str().unwrap());
    argv.extend_from_slice(&small_bed("100", "0.05"));
    let run = cli(&argv);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(summary(&plain)["unloading"].is_null());
    assert!(!plain.join("unloading.csv").exists());
    // Its checkpoint as a format-9 file (before the withdrawal: the last
    // two words, the unloading and withdrawal flags 0, cut), resumed with
    // the withdrawal: it runs from the finished state.
    let path = plain.join("checkpoint.bin");
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes[bytes.len() - 16..], [0; 16]);
    let v9 = common::checkpoint_file(&bytes, 9, &bytes[36..bytes.len() - 16]);
    std::fs::write(&path, v9).unwrap();
    let plain_s = plain.to_str().unwrap();
    let run = cli(&["bed", "--quiet", "--resume", plain_s, "--unload", "true"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(number(&summary(&plain)["unloading"], "rows") > 0.0);
    assert!(plain.join("unloading.csv").is_file());
}
