//! `granbed-cli bed` stopped by SIGINT/SIGTERM loses no finished work: the
//! run finishes its step, writes a checkpoint and the outputs so far
//! (`summary.json` marked interrupted), says how to resume and exits 130;
//! the resumed run ends with the uninterrupted run's bits, and its
//! summary's cost figures cover the whole run (the checkpoint carries the
//! counters; an older checkpoint's resume says that they cover only the
//! resumed part).
//!
//! Nothing here depends on timing: the signal handler only sets a flag
//! (`granbed_cli::signal::INTERRUPT`), so the tests set that flag — or a
//! flag of their own passed to `run_bed` — at a chosen point instead of
//! sending a signal. One test function: the CLI's flag is process-wide.

mod common;

use core::sync::atomic::{AtomicBool, Ordering};
use std::path::{Path, PathBuf};

use common::{Table, cli, number, summary};
use granbed_cli::assembly::Assembly;
use granbed_cli::bed::Scene;
use granbed_cli::bed::checkpoint::{Checkpoint, FILE_NAME, WITHDRAWAL_FILE_NAME};
use granbed_cli::bed::run::{BedObserver, BedSample, CutShort, RunControl, pour, run_bed};
use granbed_cli::model::OwnedReference;
use granbed_cli::signal::INTERRUPT;
use granbed_kernel::dem::pour::PourStatus;

fn out_dir(name: &str) -> PathBuf {
    common::fresh_dir("cli_bed_interrupt", name)
}

/// 20 coarse granules to 12 %.
const SMALL: [&str; 8] = common::small_bed("20", "0.12");

fn bed(extra: &[&str]) -> common::Run {
    let mut argv = vec!["bed", "--quiet", "-j", "1"];
    argv.extend_from_slice(extra);
    cli(&argv)
}

/// Sets `flag` once the run has written `rows` output rows (the first at
/// t = 0 included), or with `withdrawal` once the upper punch's withdrawal
/// has written `rows` rows.
struct InterruptAfter {
    rows: usize,
    seen: usize,
    flag: &'static AtomicBool,
    withdrawal: bool,
    /// A file copied (from, to) when the flag is set, before the step's
    /// checkpoint: the checkpoint of the step before.
    keep: Option<(PathBuf, PathBuf)>,
}

impl InterruptAfter {
    /// Counts a row of the loading (`withdrawal` false) or the withdrawal.
    fn count(&mut self, withdrawal: bool) {
        if withdrawal == self.withdrawal {
            self.seen += 1;
            if self.seen == self.rows {
                if let Some((from, to)) = &self.keep {
                    std::fs::copy(from, to).unwrap();
                }
                self.flag.store(true, Ordering::SeqCst);
            }
        }
    }
}

/// The wall time each withdrawal row was handed on at.
struct WithdrawalTimes(Vec<f64>);

impl BedObserver for WithdrawalTimes {
    fn sample(&mut self, _: &BedSample, _: f64) {}

    fn withdrawal(&mut self, _: &BedSample, elapsed_s: f64) {
        self.0.push(elapsed_s);
    }

    fn snapshot(&mut self, _: f64, _: &Assembly<'_>, _: &OwnedReference) -> anyhow::Result<()> {
        Ok(())
    }
}

impl BedObserver for InterruptAfter {
    fn sample(&mut self, _: &BedSample, _: f64) {
        self.count(false);
    }

    fn withdrawal(&mut self, _: &BedSample, _: f64) {
        self.count(true);
    }

    fn snapshot(&mut self, _: f64, _: &Assembly<'_>, _: &OwnedReference) -> anyhow::Result<()> {
        Ok(())
    }
}

/// Rewrites the format-11 checkpoint of `samples` output rows in `dir`,
/// which holds no withdrawal, as format 6: without format 11's withdrawal
/// flag and format 10's unloading flag (the last two u64, 0), the die wall's normal forces of format 9 (one
/// float for the window, one per row) and the phase times and counters of
/// format 7 (a length-prefixed list of 3 floats, then 7 u64s), version 6,
/// the checksum of the shorter payload. (Format 8 differs from 7 only in
/// the side values of watches, which the reader takes in any version.)
fn downgrade_to_format_6(dir: &Path, samples: usize) {
    let path = dir.join(FILE_NAME);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(common::checkpoint_version(&bytes), 11);
    assert_eq!(
        bytes[bytes.len() - 16..],
        [0; 16],
        "a checkpoint without a withdrawal, done or in progress"
    );
    let payload = &bytes[36..bytes.len() - 16 - (8 + 3 * 8 + 7 * 8) - 8 * (1 + samples)];
    std::fs::write(&path, common::checkpoint_file(&bytes, 6, payload)).unwrap();
}

/// The cost figures that do not depend on the clock.
const COUNTED: [&str; 3] = [
    "contact_sweeps_per_step",
    "pair_searches_per_step",
    "rigid_granule_step_share",
];

#[test]
fn an_interrupted_run_keeps_its_work_and_resumes_to_the_same_bits() {
    static FLAG: AtomicBool = AtomicBool::new(false);
    let (whole, parts, old) = (out_dir("whole"), out_dir("parts"), out_dir("old"));
    let (whole_s, parts_s, old_s) = (
        whole.to_str().unwrap(),
        parts.to_str().unwrap(),
        old.to_str().unwrap(),
    );

    // The uninterrupted run, into a folder holding an earlier run's
    // snapshot of a strain this one does not reach: the fresh run removes
    // it (and nothing else).
    std::fs::create_dir_all(whole.join("vtk")).unwrap();
    std::fs::write(whole.join("vtk/bed_3.vtu"), "stale").unwrap();
    std::fs::write(whole.join("vtk/notes.txt"), "mine").unwrap();
    let r = bed(&[&["--out", whole_s][..], &SMALL].concat());
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(!whole.join("vtk/bed_3.vtu").exists(), "stale snapshot left");
    assert!(whole.join("vtk/notes.txt").exists());
    assert!(whole.join("vtk/bed_1.vtu").exists());
    let whole_summary = summary(&whole);
    assert_eq!(whole_summary["interrupted"], false);
    assert_eq!(number(&whole_summary, "cost_figures_from_step"), 0.0);

    // 1. The library: a flag set after the 6th output row stops the run
    // after that step, with a checkpoint of it.
    let printed = cli(&[&["bed", "--print-scene"][..], &SMALL].concat());
    let scene = Scene::from_toml(&printed.stdout).unwrap();
    std::fs::create_dir_all(&parts).unwrap();
    let control = RunControl {
        checkpoint_dir: Some(parts.clone()),
        interrupt: Some(&FLAG),
        ..RunControl::default()
    };
    let mut observer = InterruptAfter {
        rows: 6,
        seen: 0,
        flag: &FLAG,
        withdrawal: false,
        keep: None,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let run = pool
        .install(|| run_bed(&scene, &control, &mut observer))
        .unwrap();
    assert!(run.interrupted && !run.stopped && run.error.is_none());
    assert_eq!(run.samples.len(), 6);
    let first = Checkpoint::read(&parts).unwrap();
    assert_eq!(first.state.steps, run.steps);
    assert_eq!(first.progress.counters.steps, run.steps);
    assert_eq!(first.progress.counters_from_step, 0);
    // A copy of this checkpoint in the format before the counters.
    std::fs::create_dir_all(&old).unwrap();
    std::fs::copy(parts.join(FILE_NAME), old.join(FILE_NAME)).unwrap();
    downgrade_to_format_6(&old, run.samples.len());
    let older = Checkpoint::read(&old).unwrap();
    assert_eq!(older.progress.counters_from_step, run.steps);
    assert_eq!(older.state, first.state);

    // 2. The CLI: the signal handler's flag, set already, stops the resumed
    // run after its first step — between two output rows — with exit
    // status 130, the outputs so far, and how to resume.
    INTERRUPT.store(true, Ordering::SeqCst);
    let r = bed(&["--resume", parts_s]);
    INTERRUPT.store(false, Ordering::SeqCst);
    assert_eq!(r.code, 130, "{}", r.stderr);
    assert!(
        r.stderr.contains("interrupted at C =")
            // Between two rows: the message says where the outputs end.
            && r.stderr.contains("(the outputs' last row: C = ")
            && r.stderr
                .contains(&format!("granbed-cli bed --resume {parts_s}")),
        "{}",
        r.stderr
    );
    let second = Checkpoint::read(&parts).unwrap();
    assert_eq!(second.state.steps, run.steps + 1);
    let s = summary(&parts);
    assert_eq!(s["interrupted"], true);
    // No overlap check after an interrupt: the user asked to stop.
    assert!(
        s["final_hidden_overlap"].is_null(),
        "{}",
        s["final_hidden_overlap"]
    );
    assert!(
        s["warnings"][0]
            .as_str()
            .unwrap()
            .starts_with("interrupted"),
        "{s}"
    );
    assert_eq!(number(&s, "steps"), (run.steps + 1) as f64);
    let rows = Table::read(&parts.join("compression.csv"));
    assert_eq!(rows.cells.len(), 6, "the rows written before the stop");

    // 3. Resumed to the end: the uninterrupted run's bits, and cost
    // figures over the whole run.
    let r = bed(&["--resume", parts_s]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(
        std::fs::read(whole.join("compression.csv")).unwrap(),
        std::fs::read(parts.join("compression.csv")).unwrap(),
        "interrupted twice and resumed differs from the uninterrupted run"
    );
    let s = summary(&parts);
    assert_eq!(s["interrupted"], false);
    assert!(s["final_hidden_overlap"]["rel_element"].is_number());
    assert_eq!(s["steps"], whole_summary["steps"]);
    assert_eq!(number(&s, "cost_figures_from_step"), 0.0);
    for key in COUNTED {
        assert_eq!(s[key], whole_summary[key], "{key}");
    }
    assert!(number(&s, "contact_share") > 0.0);

    // 4. A checkpoint from before the counters resumes to the same bits;
    // its cost figures cover the resumed steps only, and it says so. It
    // did not record the die wall's normal force either (format 9): the
    // rows it holds have none; its window was empty (it was taken at an
    // output row's step), so the later rows are the uninterrupted run's.
    let r = bed(&["--resume", old_s]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let text = |dir: &Path| std::fs::read_to_string(dir.join("compression.csv")).unwrap();
    let (whole_csv, old_csv) = (text(&whole), text(&old));
    let header: Vec<&str> = whole_csv.lines().next().unwrap().split(',').collect();
    let die = ["die_normal_force_n", "die_wall_pressure_pa"]
        .map(|c| header.iter().position(|h| *h == c).unwrap());
    assert_eq!(whole_csv.lines().count(), old_csv.lines().count());
    for (i, (w, o)) in whole_csv.lines().zip(old_csv.lines()).enumerate().skip(1) {
        let (w, o): (Vec<&str>, Vec<&str>) = (w.split(',').collect(), o.split(',').collect());
        for (k, (a, b)) in w.iter().zip(&o).enumerate() {
            let row = i - 1;
            if die.contains(&k) && row < run.samples.len() {
                assert_eq!(*b, "NaN", "row {row}, column {}", header[k]);
            } else {
                assert_eq!(a, b, "row {row}, column {}", header[k]);
            }
        }
    }
    let s = summary(&old);
    assert_eq!(number(&s, "cost_figures_from_step"), run.steps as f64);
    let warned = s["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("older than format 7"));
    assert!(warned, "{s}");
    assert!(r.stderr.contains("older than format 7"), "{}", r.stderr);

    // 5. Resuming a finished run takes no step, says so, and keeps the
    // cost figures; a --strain below the strain reached says so too.
    let r = bed(&["--resume", whole_s]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr.contains("no step of the loading to take"),
        "{}",
        r.stderr
    );
    let again = summary(&whole);
    for key in COUNTED {
        assert_eq!(again[key], whole_summary[key], "{key}");
    }
    let r = bed(&["--resume", whole_s, "--strain", "0.05"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr.contains("at or past the final strain 0.05"),
        "{}",
        r.stderr
    );
    assert!(
        r.stderr
            .contains("the checkpoint resumed was already past it"),
        "{}",
        r.stderr
    );

    // 6. A signal during the pour: nothing to keep, exit 130 at once.
    let fresh = out_dir("fresh");
    INTERRUPT.store(true, Ordering::SeqCst);
    let r = bed(&[&["--out", fresh.to_str().unwrap()][..], &SMALL].concat());
    INTERRUPT.store(false, Ordering::SeqCst);
    assert_eq!(r.code, 130, "{}", r.stderr);
    assert!(r.stderr.contains("nothing to resume"), "{}", r.stderr);
    assert!(!fresh.join(FILE_NAME).exists());
}

/// Sets `flag` at the pour's `checks`-th rest check and counts the pour's
/// checks and the compression's rows it sees.
struct InterruptPour {
    checks: usize,
    seen: usize,
    rows: usize,
    flag: &'static AtomicBool,
}

impl BedObserver for InterruptPour {
    fn sample(&mut self, _: &BedSample, _: f64) {
        self.rows += 1;
    }

    fn snapshot(&mut self, _: f64, _: &Assembly<'_>, _: &OwnedReference) -> anyhow::Result<()> {
        Ok(())
    }

    fn pour(&mut self, _: &PourStatus, _: f64) {
        self.seen += 1;
        if self.seen == self.checks {
            self.flag.store(true, Ordering::SeqCst);
        }
    }
}

/// An interrupt during the pour (SIGINT in a pour of thousands of spheres,
/// which runs for minutes) stops it at its next rest check, not at its
/// end: the run returns `Interrupted` naming the pour, compresses nothing
/// and writes no checkpoint. (A flag of its own: not the CLI's.)
#[test]
fn an_interrupt_during_the_pour_stops_it_at_its_next_check() {
    static FLAG: AtomicBool = AtomicBool::new(false);
    let printed = cli(&[&["bed", "--print-scene"][..], &SMALL].concat());
    let scene = Scene::from_toml(&printed.stdout).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    // The pour left alone takes more than two rest checks.
    let mut checks = 0;
    pool.install(|| pour(&scene, Some(&FLAG), &mut |_, _| checks += 1))
        .unwrap();
    assert!(checks > 2, "the pour must outlast two checks ({checks})");

    let dir = out_dir("pour");
    std::fs::create_dir_all(&dir).unwrap();
    let control = RunControl {
        checkpoint_dir: Some(dir.clone()),
        interrupt: Some(&FLAG),
        ..RunControl::default()
    };
    let mut observer = InterruptPour {
        checks: 2,
        seen: 0,
        rows: 0,
        flag: &FLAG,
    };
    let err = pool
        .install(|| run_bed(&scene, &control, &mut observer))
        .unwrap_err();
    assert!(
        err.chain()
            .any(|e| e.is::<granbed_cli::signal::Interrupted>()),
        "{err:#}"
    );
    assert!(format!("{err:#}").contains("during the pour"), "{err:#}");
    assert_eq!(
        observer.seen, 2,
        "the pour went on past the check that saw the flag"
    );
    assert_eq!(observer.rows, 0);
    assert!(!dir.join(FILE_NAME).exists());
}

/// An interrupt during the upper punch's withdrawal (scene `unload`, the
/// published scene's) stops it after the step it is in: the run says it
/// was interrupted, its withdrawal is cut short after the rows so far, the
/// checkpoint is the loading's end without it, and the withdrawal's own
/// checkpoint (`withdrawal.bin`, written here every step) holds it where it
/// stopped. Resumed, the run goes on from there (the rows so far are
/// handed on at once, at the withdrawal's wall time then), to the rows and
/// figures of a withdrawal never interrupted, bit for bit, and the
/// withdrawal's checkpoint goes. So does a resume from the checkpoint of a
/// step between two rows (its averaging window open), kept as the second
/// row came; a withdrawal checkpoint of another loading (one row's force
/// changed in its last bit) is not used but removed, and the withdrawal
/// runs from the loading's end, to the same bits.
#[test]
fn an_interrupted_withdrawal_goes_on_from_its_checkpoint() {
    static FLAG: AtomicBool = AtomicBool::new(false);
    let printed = cli(&[&["bed", "--print-scene"][..], &SMALL].concat());
    let mut scene = Scene::from_toml(&printed.stdout).unwrap();
    assert!(scene.unload, "the published scene unloads");
    // A checkpoint every step (the interval changes no bit), and physical
    // masses: steps short enough that a row of the withdrawal takes
    // several (with the published ×20, one).
    scene.checkpoint_interval_minutes = 1e-9;
    scene.mass_scaling = 1.0;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (cut, whole) = (out_dir("withdrawal_cut"), out_dir("withdrawal_whole"));
    let run_into = |dir: &Path, observer: &mut InterruptAfter, interrupt| {
        std::fs::create_dir_all(dir).unwrap();
        let control = RunControl {
            checkpoint_dir: Some(dir.to_path_buf()),
            interrupt,
            ..RunControl::default()
        };
        pool.install(|| run_bed(&scene, &control, observer))
            .unwrap()
    };
    let between = out_dir("withdrawal_between_rows");
    std::fs::create_dir_all(&between).unwrap();
    let mut observer = InterruptAfter {
        rows: 2,
        seen: 0,
        flag: &FLAG,
        withdrawal: true,
        keep: Some((
            cut.join(WITHDRAWAL_FILE_NAME),
            between.join(WITHDRAWAL_FILE_NAME),
        )),
    };
    let run = run_into(&cut, &mut observer, Some(&FLAG));
    let u = run.unloading.as_ref().expect("a withdrawal");
    assert!(run.interrupted && run.error.is_none());
    assert_eq!(u.samples.len(), 2);
    // Stopped after the step of its second row, at that row's strain.
    assert_eq!(
        u.cut_short,
        Some(CutShort::Interrupted {
            strain: u.samples[1].strain
        })
    );
    let checkpoint = Checkpoint::read(&cut).unwrap();
    assert!(checkpoint.progress.unloading.is_none());
    assert_eq!(checkpoint.state.steps, run.steps, "the loading's end");
    let saved = Checkpoint::read_from(&cut, WITHDRAWAL_FILE_NAME).unwrap();
    let progress = saved.progress.withdrawal.as_ref().expect("a withdrawal");
    assert_eq!(progress.turn_steps, run.steps);
    assert_eq!(progress.rows, u.samples, "the rows so far");
    assert!(saved.state.steps > run.steps, "the state where it stopped");
    // The step before the second row's: one row, the window open.
    let open = Checkpoint::read_from(&between, WITHDRAWAL_FILE_NAME).unwrap();
    let open_progress = open.progress.withdrawal.as_ref().unwrap();
    assert_eq!(open_progress.rows, u.samples[..1]);
    assert!(open_progress.window.time > 0.0, "an open window");
    assert_eq!(open.state.steps + 1, saved.state.steps);
    // Another loading's withdrawal: a row's force moved by one bit.
    let stale = out_dir("withdrawal_stale");
    std::fs::create_dir_all(&stale).unwrap();
    let mut other = saved.clone();
    let f = &mut other.progress.samples[1].upper_force_n;
    *f = f64::from_bits(f.to_bits() ^ 1);
    other.write_as(&stale, WITHDRAWAL_FILE_NAME).unwrap();

    let mut quiet = InterruptAfter {
        rows: usize::MAX,
        seen: 0,
        flag: &FLAG,
        withdrawal: true,
        keep: None,
    };
    let straight = run_into(&whole, &mut quiet, None);
    let straight = straight.unloading.expect("withdrawn");
    // Resumes `dir` from the loading's checkpoint `loading`: the
    // withdrawal's rows and the wall times they were handed on at.
    let resume = |dir: &Path, loading: Checkpoint| {
        let mut seen = WithdrawalTimes(Vec::new());
        let resumed = pool
            .install(|| {
                run_bed(
                    &scene,
                    &RunControl {
                        resume: Some(loading),
                        checkpoint_dir: Some(dir.to_path_buf()),
                        ..RunControl::default()
                    },
                    &mut seen,
                )
            })
            .unwrap();
        assert!(!resumed.interrupted);
        assert!(!dir.join(WITHDRAWAL_FILE_NAME).exists());
        assert!(Checkpoint::read(dir).unwrap().progress.unloading.is_some());
        let u = resumed.unloading.expect("withdrawn");
        assert!(u.cut_short.is_none() && u.lift_off_strain.is_finite());
        assert_eq!(u.samples, straight.samples);
        assert_eq!(
            u.lift_off_strain.to_bits(),
            straight.lift_off_strain.to_bits()
        );
        seen.0
    };
    // The rows so far came from the withdrawal's checkpoint, before any
    // step: at its wall time.
    let seen = resume(&cut, checkpoint.clone());
    assert_eq!(seen[..2], [progress.wall_time_s; 2], "{seen:?}");
    assert!(seen[2] > progress.wall_time_s);
    let seen = resume(&between, checkpoint.clone());
    assert_eq!(seen[0], open_progress.wall_time_s, "{seen:?}");
    assert!(seen[1] > open_progress.wall_time_s);
    // The stale one is not used: every row comes from a step.
    let seen = resume(&stale, checkpoint);
    assert!(seen[0] < seen[1], "{seen:?}");
}
