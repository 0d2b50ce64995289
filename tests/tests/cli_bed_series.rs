//! `granbed-cli bed --resume DIR` on the directory of a series (`--types`,
//! `--seeds`): the series loses no finished work. A member never started is
//! run from the series' own scene and, for `--types`, its stored pour; a
//! member stopped part way continues from its checkpoint; either ends with
//! the bits of the uninterrupted series, and DIR's tables are written again
//! (a refit's windows reach them). On CI-sized beds (12 coarse granules).

mod common;

use std::path::{Path, PathBuf};

use common::{Table, cli, number, summary};

fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_bed_series", name)
}

const BED: [&str; 8] = common::small_bed("12", "0.15");
/// Fit windows the short runs reach.
const WINDOWS: [&str; 4] = [
    "--kawakita-min-strain",
    "0.05",
    "--heckel-min-strain",
    "0.05",
];

fn bed(extra: &[&str]) -> common::Run {
    let mut argv = vec!["bed", "--quiet", "-j", "2"];
    argv.extend_from_slice(extra);
    cli(&argv)
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The table's lines without its wall-time column (which differs from run
/// to run).
fn without_wall_time(path: &Path) -> Vec<String> {
    let skip = Table::read(path).col("wall_time_s");
    String::from_utf8(read(path))
        .unwrap()
        .lines()
        .map(|line| {
            line.split(',')
                .enumerate()
                .filter(|&(c, _)| c != skip)
                .map(|(_, cell)| cell)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

#[test]
fn a_series_of_types_resumes_as_a_whole() {
    let full = out_dir("types_full");
    let mut argv = vec!["--out", full.to_str().unwrap(), "--types", "B1,B2"];
    argv.extend_from_slice(&BED);
    argv.extend_from_slice(&WINDOWS);
    let run = bed(&argv);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(full.join("series.json").is_file());

    // A series interrupted before B1 was run: no B1, no comparison. (The
    // series poured with B2's sphere density, the scene's type: a fresh pour
    // for B1 would be another bed.)
    let dir = out_dir("types");
    let mut argv = vec!["--out", dir.to_str().unwrap(), "--types", "B1,B2"];
    argv.extend_from_slice(&BED);
    argv.extend_from_slice(&WINDOWS);
    assert_eq!(bed(&argv).code, 0);
    std::fs::remove_dir_all(dir.join("B1")).unwrap();
    for f in ["comparison.csv", "comparison.json"] {
        std::fs::remove_file(dir.join(f)).unwrap();
    }
    let run = bed(&["--resume", dir.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_eq!(
        read(&dir.join("B1/compression.csv")),
        read(&full.join("B1/compression.csv")),
        "B1 started by the resume compresses the series' pour"
    );
    assert_eq!(
        without_wall_time(&dir.join("comparison.csv")),
        without_wall_time(&full.join("comparison.csv"))
    );

    // B2 stopped part way (the same pour: a single B2 run of the scene pours
    // with B2's sphere density and seed, as the series did).
    let mut argv = vec![
        "--out",
        dir.to_str().unwrap(),
        "--type",
        "B2",
        "--stop-at-strain",
        "0.06",
        "--overwrite",
    ];
    argv.extend_from_slice(&BED);
    argv.extend_from_slice(&WINDOWS);
    let b2 = dir.join("B2");
    argv[1] = b2.to_str().unwrap();
    assert_eq!(bed(&argv).code, 0);
    assert_ne!(
        read(&b2.join("compression.csv")),
        read(&full.join("B2/compression.csv"))
    );
    let run = bed(&["--resume", dir.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_eq!(
        read(&b2.join("compression.csv")),
        read(&full.join("B2/compression.csv")),
        "B2 continued from its checkpoint ends with the series' bits"
    );

    // A refit of the whole series: the tables carry the new windows' fits.
    let before = Table::read(&dir.join("comparison.csv")).num("heckel_yield_pressure_pa");
    let run = bed(&[
        "--resume",
        dir.to_str().unwrap(),
        "--heckel-min-strain",
        "0.1",
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let after = Table::read(&dir.join("comparison.csv")).num("heckel_yield_pressure_pa");
    for ((t, a), b) in ["B1", "B2"].iter().zip(&after).zip(&before) {
        let s = summary(&dir.join(t));
        assert_eq!(
            number(&s, "heckel_yield_pressure_pa").to_bits(),
            a.to_bits()
        );
        assert_ne!(a.to_bits(), b.to_bits(), "{t}: the refit changed nothing");
    }
}

#[test]
fn a_series_of_seeds_resumes_as_a_whole() {
    let full = out_dir("seeds_full");
    let mut argv = vec!["--out", full.to_str().unwrap(), "--seeds", "3,1"];
    argv.extend_from_slice(&BED);
    assert_eq!(bed(&argv).code, 0);

    let dir = out_dir("seeds");
    let mut argv = vec!["--out", dir.to_str().unwrap(), "--seeds", "3,1"];
    argv.extend_from_slice(&BED);
    assert_eq!(bed(&argv).code, 0);
    std::fs::remove_dir_all(dir.join("seed_1")).unwrap();
    std::fs::remove_file(dir.join("seeds.csv")).unwrap();
    let run = bed(&["--resume", dir.to_str().unwrap()]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert_eq!(
        read(&dir.join("seed_1/compression.csv")),
        read(&full.join("seed_1/compression.csv"))
    );
    assert_eq!(
        without_wall_time(&dir.join("seeds.csv")),
        without_wall_time(&full.join("seeds.csv"))
    );
    assert_eq!(
        read(&dir.join("seeds_spread.csv")),
        read(&full.join("seeds_spread.csv"))
    );
}

#[test]
fn a_series_resume_refuses_what_it_cannot_do() {
    let dir = out_dir("refusals");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("series.json"), "{\"format\": 1}").unwrap();
    let run = bed(&["--resume", dir.to_str().unwrap()]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(
        run.stderr.contains("series.json") && run.stderr.contains("kind"),
        "{}",
        run.stderr
    );
    let run = bed(&["--resume", dir.to_str().unwrap(), "--stop-at-strain", "0.1"]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("--stop-at-strain"), "{}", run.stderr);

    // A directory of runs without series.json (an older series) is pointed
    // to its runs.
    let old = out_dir("old_series");
    std::fs::create_dir_all(old.join("A1")).unwrap();
    std::fs::write(old.join("A1/checkpoint.bin"), b"").unwrap();
    let run = bed(&["--resume", old.to_str().unwrap()]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("A1"), "{}", run.stderr);
}

/// A series and a single run do not share a directory: each refuses the
/// other's files (which would mix, and `--resume DIR` would take the wrong
/// one), and `--overwrite` removes them first.
#[test]
fn a_series_and_a_single_run_keep_out_of_each_other() {
    let dir = out_dir("mixed");
    let out = dir.to_str().unwrap();
    let short = common::small_bed("8", "0.03");
    let single = |extra: &[&str]| {
        let mut argv = vec!["--out", out];
        argv.extend_from_slice(&short);
        argv.extend_from_slice(extra);
        bed(&argv)
    };
    let series = |extra: &[&str]| {
        let mut argv = vec!["--out", out, "--types", "B1,B2"];
        argv.extend_from_slice(&short);
        argv.extend_from_slice(extra);
        bed(&argv)
    };
    assert_eq!(single(&[]).code, 0);
    let run = series(&[]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("holds a single run"), "{}", run.stderr);
    assert!(!dir.join("series.json").exists());
    let run = series(&["--overwrite"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    for f in ["checkpoint.bin", "summary.json", "compression.csv"] {
        assert!(
            !dir.join(f).exists(),
            "{f} of the single run left beside the series"
        );
    }
    assert!(dir.join("series.json").is_file() && dir.join("B1/summary.json").is_file());
    // report.html is now the series' page, linking each member's report.
    let report = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(report.contains("granule types B1, B2"), "{report}");
    for t in ["B1", "B2"] {
        assert!(report.contains(&format!("<a href=\"{t}/report.html\">{t}</a>")));
        assert!(dir.join(t).join("report.html").is_file());
    }

    // A series refused for its scene after --overwrite was given removes
    // nothing: the checks come first.
    assert_eq!(single(&["--overwrite"]).code, 0);
    let scene = dir.with_extension("toml");
    common::write_scene_with_material(&scene, "yield_stress_pa = 50000.0");
    let run = bed(&[
        "--out",
        out,
        "--scene",
        scene.to_str().unwrap(),
        "--types",
        "A2,C2",
        "--overwrite",
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(dir.join("summary.json").is_file() && dir.join("checkpoint.bin").is_file());
    assert_eq!(series(&["--overwrite"]).code, 0);

    let run = single(&[]);
    assert_eq!(run.code, 2, "{}", run.stderr);
    assert!(run.stderr.contains("holds a series"), "{}", run.stderr);
    let run = single(&["--overwrite"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(!dir.join("series.json").exists() && !dir.join("comparison.csv").exists());
    assert!(dir.join("checkpoint.bin").is_file() && dir.join("B1/summary.json").is_file());
    let report = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(
        !report.contains("granule types B1, B2") && report.contains("<h2>Summary</h2>"),
        "report.html is not the single run's"
    );
}

/// A checkpoint in a member's directory that is not a run of the member
/// (another seed, say) is refused by name, not taken into the tables; the
/// scene of a series prints without a step; and a series.json whose pour
/// names no type is refused before anything runs.
#[test]
fn a_series_resume_takes_only_its_own_runs() {
    let dir = out_dir("own");
    let out = dir.to_str().unwrap();
    let short = common::small_bed("8", "0.03");
    let mut argv = vec!["--out", out, "--seeds", "1,2"];
    argv.extend_from_slice(&short);
    assert_eq!(bed(&argv).code, 0);
    let tables = read(&dir.join("seeds.csv"));

    // --print-scene: the series' scene, no run.
    let r = cli(&["bed", "--resume", out, "--print-scene"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let scene = granbed_cli::bed::Scene::from_toml(&r.stdout).unwrap();
    assert_eq!(scene.granules, 8);
    assert_eq!(read(&dir.join("seeds.csv")), tables);

    // seed_2 replaced by a run of seed 5: refused, naming it.
    let seed_2 = dir.join("seed_2");
    let mut argv = vec!["--out", seed_2.to_str().unwrap(), "--seed", "5"];
    argv.extend_from_slice(&short);
    assert_eq!(bed(&argv).code, 0);
    let r = bed(&["--resume", out]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("seed 2") && r.stderr.contains("not a run of this series"),
        "{}",
        r.stderr
    );
    assert_eq!(read(&dir.join("seeds.csv")), tables);

    // A new series into the directory clears the members' old checkpoints
    // and the tables of the other kind.
    std::fs::remove_dir_all(&seed_2).unwrap();
    let mut argv = vec!["--out", out, "--types", "B1,B2"];
    argv.extend_from_slice(&short);
    assert_eq!(bed(&argv).code, 0);
    assert!(!dir.join("seeds.csv").exists() && dir.join("comparison.csv").is_file());

    // A pour that names no type.
    let text = std::fs::read_to_string(dir.join("series.json")).unwrap();
    std::fs::write(
        dir.join("series.json"),
        text.replace("\"granule_type\": \"B2\"", "\"granule_type\": \"Z9\""),
    )
    .unwrap();
    let before = read(&dir.join("B1/compression.csv"));
    let r = bed(&["--resume", out]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("`Z9` is none of A1 ... C3"),
        "{}",
        r.stderr
    );
    assert_eq!(read(&dir.join("B1/compression.csv")), before);
}
