//! Fuzzing of what `granbed-cli bed` reads from disk (issue #9): scene
//! TOML and checkpoints, mutated at random. Every read must return — no
//! panic — with a clear error or a valid value:
//! * scenes: the published scene with bytes flipped, inserted, deleted or
//!   the text cut short; a scene that parses must also validate;
//! * checkpoints: a real small-bed checkpoint truncated, with bytes
//!   flipped (caught by the checksum), with its version changed, and with
//!   its payload mutated *and the checksum recomputed*, which drives the
//!   payload decoder itself with hostile lengths and values. A checkpoint
//!   that decodes is also restored into the bed (`--resume`), which must
//!   accept it or refuse it with an error.
//!
//! `PROPTEST_CASES` sets the cases per property (default below).

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use granbed_cli::bed::checkpoint::{Checkpoint, FILE_NAME};
use granbed_cli::bed::{DEFAULT_SCENE, Scene};
use proptest::prelude::*;

fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// One edit of a byte string.
#[derive(Clone, Debug)]
enum Edit {
    Flip(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    Truncate(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Flip(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Insert(i, b)),
        any::<usize>().prop_map(Edit::Delete),
        any::<usize>().prop_map(Edit::Truncate),
    ]
}

fn apply(bytes: &mut Vec<u8>, edits: &[Edit]) {
    for e in edits {
        let n = bytes.len().max(1);
        match *e {
            Edit::Flip(i, b) => {
                if let Some(x) = bytes.get_mut(i % n) {
                    *x ^= b.max(1);
                }
            }
            Edit::Insert(i, b) => bytes.insert(i % (bytes.len() + 1), b),
            Edit::Delete(i) => {
                if !bytes.is_empty() {
                    bytes.remove(i % n);
                }
            }
            Edit::Truncate(i) => bytes.truncate(i % n),
        }
    }
}

/// Scene values that stress the validation, spliced into the text.
fn hostile_value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_owned()),
        Just("inf".to_owned()),
        Just("-inf".to_owned()),
        Just("-1".to_owned()),
        Just("0".to_owned()),
        Just("1e308".to_owned()),
        Just("18446744073709551616".to_owned()),
        Just("\"x\"".to_owned()),
        Just("[]".to_owned()),
        any::<f64>().prop_map(|v| format!("{v:?}")),
        any::<i64>().prop_map(|v| v.to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(2000)))]

    #[test]
    fn mutated_scenes_parse_or_fail_cleanly(edits in proptest::collection::vec(edit(), 1..8)) {
        let mut bytes = DEFAULT_SCENE.as_bytes().to_vec();
        apply(&mut bytes, &edits);
        if let Ok(text) = core::str::from_utf8(&bytes)
            && let Ok(scene) = Scene::from_toml(text)
        {
            prop_assert!(scene.validate().is_ok());
        }
    }

    #[test]
    fn hostile_scene_values_are_rejected_or_valid(
        line in 0usize..64,
        value in hostile_value(),
    ) {
        // Replace the value of one `key = value` line of the scene.
        let lines: Vec<&str> = DEFAULT_SCENE.lines().collect();
        let assignments: Vec<usize> = (0..lines.len())
            .filter(|&i| lines[i].contains(" = ") && !lines[i].starts_with('#'))
            .collect();
        let target = assignments[line % assignments.len()];
        let key = lines[target].split(" = ").next().unwrap();
        let text: String = lines
            .iter()
            .enumerate()
            .map(|(i, l)| if i == target { format!("{key} = {value}\n") } else { format!("{l}\n") })
            .collect();
        match Scene::from_toml(&text) {
            Ok(scene) => prop_assert!(scene.validate().is_ok()),
            Err(e) => {
                let message = format!("{e:#}");
                prop_assert!(!message.is_empty());
            }
        }
    }
}

/// A small bed's checkpoint (4 coarse granules stopped at 0.5 % strain),
/// made once per test binary: its directory and bytes.
fn base_checkpoint() -> &'static (PathBuf, Vec<u8>) {
    static BASE: OnceLock<(PathBuf, Vec<u8>)> = OnceLock::new();
    BASE.get_or_init(|| {
        let dir = common::fresh_dir("fuzz_files", "base");
        let run = common::cli(&[
            "bed",
            "--quiet",
            "--granules",
            "4",
            "--mesh",
            "4x1",
            "--die-diameter-mm",
            "4.5",
            "--strain",
            "0.01",
            "--stop-at-strain",
            "0.005",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert_eq!(run.code, 0, "{}", run.stderr);
        let bytes = std::fs::read(dir.join(FILE_NAME)).unwrap();
        (dir, bytes)
    })
}

/// Writes `bytes` as the checkpoint of a fresh directory `name`.
fn write_checkpoint(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = common::fresh_dir("fuzz_files", name);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(FILE_NAME), bytes).unwrap();
    dir
}

fn read(dir: &Path) -> Result<Checkpoint, String> {
    Checkpoint::read(dir).map_err(|e| format!("{e:#}"))
}

#[test]
fn the_base_checkpoint_reads_back() {
    let (dir, _) = base_checkpoint();
    read(dir).expect("an intact checkpoint reads");
}

#[test]
fn truncated_checkpoints_are_refused_with_a_reason() {
    let (_, bytes) = base_checkpoint();
    // Every cut in the header, then cuts spread over the payload.
    let cuts = (0..64).chain((64..bytes.len()).step_by(bytes.len() / 200 + 1));
    for cut in cuts {
        let dir = write_checkpoint("truncated", &bytes[..cut]);
        let e = read(&dir).expect_err("a truncated checkpoint must be refused");
        assert!(
            e.contains("not a usable checkpoint"),
            "cut at {cut}: unclear error: {e}"
        );
    }
}

/// Bytes after the payload are named as such, not as a truncation: the
/// file was appended to.
#[test]
fn bytes_after_the_payload_are_named() {
    let (_, bytes) = base_checkpoint();
    let mut b = bytes.clone();
    b.extend_from_slice(b"garbage");
    let e = read(&write_checkpoint("appended", &b)).unwrap_err();
    assert!(e.contains("7 bytes after its"), "{e}");
    let e = read(&write_checkpoint("cut", &bytes[..bytes.len() - 3])).unwrap_err();
    assert!(e.contains("truncated"), "{e}");
}

/// A state that is not positive definite (its determinant positive) is
/// refused on reading, naming the granule and the element: the element
/// loop tests only the determinant.
#[test]
fn an_indefinite_state_in_a_checkpoint_is_named() {
    let (dir, _) = base_checkpoint();
    let mut ck = read(dir).unwrap();
    ck.state.granules[1].cp_inv[3] = [-1.0, -1.0, 1.0, 0.0, 0.0, 0.0];
    let edited = common::fresh_dir("fuzz_files", "indefinite");
    std::fs::create_dir_all(&edited).unwrap();
    ck.write(&edited).unwrap();
    let e = read(&edited).unwrap_err();
    assert!(
        e.contains("granule 1, element state 3") && e.contains("not positive definite"),
        "{e}"
    );
}

#[test]
fn a_wrong_version_is_named() {
    let (_, bytes) = base_checkpoint();
    let mut b = bytes.clone();
    b[16..20].copy_from_slice(&99u32.to_le_bytes());
    let e = read(&write_checkpoint("version", &b)).unwrap_err();
    assert!(e.contains("format version 99"), "{e}");
}

/// The 8-byte words at which the checkpoints of `ck` before and after
/// `edit` differ (their offsets in the file), with the unedited bytes.
/// Each edited word must differ in its lowest byte (the first, little
/// endian), where the word is taken to start: see [`flip`].
fn edited_words(ck: &Checkpoint, edit: impl Fn(&mut Checkpoint)) -> (Vec<usize>, Vec<u8>) {
    let bytes = |ck: &Checkpoint, name: &str| {
        let d = common::fresh_dir("fuzz_files", name);
        std::fs::create_dir_all(&d).unwrap();
        ck.write(&d).unwrap();
        std::fs::read(d.join(FILE_NAME)).unwrap()
    };
    let before = bytes(ck, "edit_before");
    let mut edited = ck.clone();
    edit(&mut edited);
    let after = bytes(&edited, "edit_after");
    assert_eq!(before.len(), after.len());
    let mut words: Vec<usize> = Vec::new();
    for k in (36..before.len()).filter(|&k| before[k] != after[k]) {
        // A word starts on the first differing byte not inside the last.
        if words.last().is_none_or(|&w| k >= w + 8) {
            words.push(k);
        }
    }
    (words, before)
}

/// Bytes near the end of a format-7 payload that older formats lack: the
/// phase times (a length-prefixed list of 3 floats) and 7 counters.
const COUNTER_BYTES: usize = 8 + 3 * 8 + 7 * 8;

/// The offset of format 10's last word in the checkpoint file `bytes` of
/// a run without a withdrawal: its unloading flag, 0 (cut from every older
/// format), before format 11's last word.
fn unloading_word(bytes: &[u8]) -> usize {
    bytes.len() - 16
}

/// The offset of format 11's last word in the checkpoint file `bytes` of
/// a run without a withdrawal in progress: its withdrawal flag, 0 (cut
/// from every older format).
fn withdrawal_word(bytes: &[u8]) -> usize {
    bytes.len() - 8
}

/// The offsets of the 8-byte words of the counters before the unloading
/// flag of the checkpoint file `bytes` (cut from formats before 7).
fn counter_words(bytes: &[u8]) -> Vec<usize> {
    let end = unloading_word(bytes);
    (end - COUNTER_BYTES..end).step_by(8).collect()
}

/// `x` with its sign and lowest mantissa bit flipped: it differs from `x`
/// in the first and the last byte of its word.
fn flip(x: f64) -> f64 {
    f64::from_bits(x.to_bits() ^ (1 << 63 | 1))
}

/// `bytes` (a checkpoint file) with the 8-byte words at `cut` removed,
/// relabelled `version` under a fresh length and checksum.
fn older(bytes: &[u8], cut: &[usize], version: u32) -> Vec<u8> {
    let mut payload = Vec::new();
    let mut from = 36;
    for &k in cut {
        payload.extend_from_slice(&bytes[from..k]);
        from = k + 8;
    }
    payload.extend_from_slice(&bytes[from..]);
    common::checkpoint_file(bytes, version, &payload)
}

/// Checkpoints of older formats still read: version 9 (before the
/// upper punch's withdrawal) with none; version 8 (before the die
/// wall's normal forces) with those NaN (not recorded); and without the
/// phase times and counters of version 7 (counted from the checkpoint's
/// step) and the die forces: version 4 (before the
/// samples' kinetic energy relative to the imposed compression) with that
/// energy NaN (not recorded), version 3 (before the mass factors and the
/// undeformed step as well) with every factor 1 and no undeformed step
/// (the resuming run keeps its own), version 2 (before the per-granule
/// flags word as well) with every granule deformable too. The older bytes
/// are made from this build's own: two checkpoints of one state that
/// differ only in a field differ only in its words, which are cut out.
#[test]
fn versions_2_to_10_checkpoints_read_with_the_fields_they_lack_at_their_defaults() {
    let (dir, _) = base_checkpoint();
    let mut ck = read(dir).unwrap();
    for g in &mut ck.state.granules {
        (g.rigid, g.mass_factor) = (false, 1.0);
    }
    let granules = ck.state.granules.len();
    let (flags, _) = edited_words(&ck, |c| {
        c.state.granules.iter_mut().for_each(|g| g.rigid = true)
    });
    let (factors, _) = edited_words(&ck, |c| {
        c.state
            .granules
            .iter_mut()
            .for_each(|g| g.mass_factor = flip(1.0))
    });
    let (step, _) = edited_words(&ck, |c| {
        c.state.undeformed_step = flip(c.state.undeformed_step)
    });
    let (relative, _) = edited_words(&ck, |c| {
        c.progress
            .samples
            .iter_mut()
            .for_each(|s| s.kinetic_relative_j = flip(s.kinetic_relative_j))
    });
    // Version 9's die-wall normal forces: the window's, then each row's.
    let flip_die = |c: &mut Checkpoint| {
        c.progress.window.die_normal = flip(c.progress.window.die_normal);
        c.progress
            .samples
            .iter_mut()
            .for_each(|s| s.die_normal_force_n = flip(s.die_normal_force_n))
    };
    let (die, bytes) = edited_words(&ck, flip_die);
    assert_eq!(
        (flags.len(), factors.len(), step.len(), relative.len()),
        (granules, granules, 1, ck.progress.samples.len())
    );
    assert!(!relative.is_empty(), "the base checkpoint has no samples");
    assert_eq!(die.len(), 1 + ck.progress.samples.len());
    // An older file's window holds no die force: NaN, or 0 if the window
    // is empty (a checkpoint taken at an output row's step, as this one).
    let empty = ck.progress.window.time == 0.0;
    let unrecorded_window = |x: f64| if empty { x == 0.0 } else { x.is_nan() };
    // Each factor follows its granule's flags word.
    assert!(flags.iter().zip(&factors).all(|(f, k)| *k == f + 8));
    // An older file's state, its relative kinetic energies checked NaN and
    // then set to this build's, so that the rest compares bit for bit.
    let read_older = |name: &str, bytes: &[u8], version: u32| {
        let mut old = read(&write_checkpoint(name, bytes))
            .unwrap_or_else(|e| panic!("a version {version} checkpoint reads: {e}"));
        assert_eq!(old.progress.samples.len(), ck.progress.samples.len());
        assert_eq!(old.progress.counters, Default::default());
        assert_eq!(old.progress.counters_from_step, ck.state.steps);
        old.progress.counters = ck.progress.counters;
        old.progress.counters_from_step = ck.progress.counters_from_step;
        assert!(unrecorded_window(old.progress.window.die_normal));
        old.progress.window.die_normal = ck.progress.window.die_normal;
        for (o, s) in old.progress.samples.iter_mut().zip(&ck.progress.samples) {
            assert!(
                o.die_normal_force_n.is_nan(),
                "version {version}: no die-wall force"
            );
            o.die_normal_force_n = s.die_normal_force_n;
            if version <= 4 {
                assert!(
                    o.kinetic_relative_j.is_nan(),
                    "version {version}: not recorded"
                );
                o.kinetic_relative_j = s.kinetic_relative_j;
            }
        }
        old
    };
    let counters = counter_words(&bytes);
    let (unloading, withdrawal) = (unloading_word(&bytes), withdrawal_word(&bytes));
    assert_eq!(bytes[unloading..], [0; 16], "no withdrawal: flags 0");
    let cut_of = |parts: &[&Vec<usize>]| {
        let mut cut: Vec<usize> = parts
            .iter()
            .flat_map(|p| p.iter().copied())
            .chain(counters.iter().copied())
            .chain(die.iter().copied())
            .chain([unloading, withdrawal])
            .collect();
        cut.sort_unstable();
        cut
    };

    // Version 10: all but the flag of a withdrawal in progress.
    let v10 = older(&bytes, &[withdrawal], 10);
    let v10_read = read(&write_checkpoint("version10", &v10))
        .unwrap_or_else(|e| panic!("a version 10 checkpoint reads: {e}"));
    assert_eq!(v10_read, ck, "version 10 reads as the same state");

    // Version 9: all but the unloading flag.
    let v9 = older(&bytes, &[unloading, withdrawal], 9);
    let v9_read = read(&write_checkpoint("version9", &v9))
        .unwrap_or_else(|e| panic!("a version 9 checkpoint reads: {e}"));
    assert_eq!(v9_read, ck, "version 9 reads as the same state");

    // Version 8: all but the die-wall forces (the counters are kept).
    let mut v8_cut = die.clone();
    v8_cut.extend([unloading, withdrawal]);
    v8_cut.sort_unstable();
    let v8 = older(&bytes, &v8_cut, 8);
    let mut v8_read = read(&write_checkpoint("version8", &v8))
        .unwrap_or_else(|e| panic!("a version 8 checkpoint reads: {e}"));
    assert_eq!(v8_read.progress.counters, ck.progress.counters);
    assert!(unrecorded_window(v8_read.progress.window.die_normal));
    v8_read.progress.window.die_normal = ck.progress.window.die_normal;
    for (o, s) in v8_read
        .progress
        .samples
        .iter_mut()
        .zip(&ck.progress.samples)
    {
        assert!(
            o.die_normal_force_n.is_nan(),
            "version 8: no die-wall force"
        );
        o.die_normal_force_n = s.die_normal_force_n;
    }
    assert_eq!(v8_read, ck, "version 8 reads as the same state");
    // A version 8 file whose window had begun: its die force is unknown.
    let mut begun = ck.clone();
    begun.progress.window.time = 1e-4;
    begun.progress.window.die_normal = 0.5;
    let (mut die_begun, begun_bytes) = edited_words(&begun, flip_die);
    die_begun.extend([unloading_word(&begun_bytes), withdrawal_word(&begun_bytes)]);
    let v8_begun = older(&begun_bytes, &die_begun, 8);
    let read_begun = read(&write_checkpoint("version8_begun", &v8_begun)).unwrap();
    assert_eq!(read_begun.progress.window.time, 1e-4);
    assert!(read_begun.progress.window.die_normal.is_nan());

    let v4 = older(&bytes, &cut_of(&[&relative]), 4);
    assert_eq!(
        read_older("version4", &v4, 4),
        ck,
        "version 4 reads as the same state"
    );

    let mut expected = ck.clone();
    expected.state.undeformed_step = 0.0;
    let v3 = older(&bytes, &cut_of(&[&relative, &step, &factors]), 3);
    assert_eq!(
        read_older("version3", &v3, 3),
        expected,
        "version 3 reads as the same state, factors 1"
    );

    let mut v2 = older(&bytes, &cut_of(&[&relative, &step, &factors, &flags]), 2);
    assert_eq!(
        read_older("version2", &v2, 2),
        expected,
        "version 2 reads as the same state, all deformable"
    );
    // The same bytes labelled version 3 lack the flags: refused.
    v2[16..20].copy_from_slice(&3u32.to_le_bytes());
    read(&write_checkpoint("version2as3", &v2)).expect_err("flags missing");
}

/// `n` rows of a withdrawal after the loading's last row `last`: the strain
/// falling by 10⁻⁴ a row over 10 steps, distinct forces, the mean strains
/// continuing from `last`'s.
fn withdrawal_rows(
    last: &granbed_cli::bed::run::BedSample,
    n: u32,
) -> Vec<granbed_cli::bed::run::BedSample> {
    let mut rows: Vec<_> = (1..=n)
        .map(|k| granbed_cli::bed::run::BedSample {
            strain: last.strain - 1e-4 * f64::from(k),
            steps: last.steps + 10 * u64::from(k),
            upper_force_n: 1.0 / f64::from(k),
            die_normal_force_n: 0.25 * f64::from(k),
            ..*last
        })
        .collect();
    granbed_cli::bed::run::set_mean_strains_after(Some(last), &mut rows);
    rows
}

/// A checkpoint with a withdrawal (format 10) reads back to the same
/// rows, lift-off and wall time, the rows' mean strains continuing from
/// the loading's last row; a flag other than 0 or 1 is refused by name.
#[test]
fn a_withdrawal_in_a_checkpoint_reads_back() {
    use granbed_cli::bed::run::Unloading;
    let (dir, _) = base_checkpoint();
    let mut ck = read(dir).unwrap();
    let last = *ck.progress.samples.last().unwrap();
    let rows = withdrawal_rows(&last, 2);
    assert!(rows[0].mean_strain < last.strain && rows[0].mean_strain > rows[0].strain);
    ck.progress.unloading = Some(Unloading {
        samples: rows,
        lift_off_strain: last.strain - 1.5e-4,
        wall_time_s: 0.25,
        cut_short: None,
    });
    let d = common::fresh_dir("fuzz_files", "withdrawal");
    std::fs::create_dir_all(&d).unwrap();
    ck.write(&d).unwrap();
    assert_eq!(read(&d).unwrap(), ck);
    // The flag is the word after the counters, where a file without a
    // withdrawal ends but for the flag of one in progress.
    let (_, without) = base_checkpoint();
    let bytes = std::fs::read(d.join(FILE_NAME)).unwrap();
    let e = with_flag_2(&bytes, unloading_word(without), "withdrawal_flag");
    assert!(e.contains("unknown unloading flag 2"), "{e}");
}

/// The checkpoint file `bytes` with its flag word at `flag`, 1, set to 2
/// under a valid checksum: the error reading it (written as `name`).
fn with_flag_2(bytes: &[u8], flag: usize, name: &str) -> String {
    assert_eq!(bytes[flag..flag + 8], 1u64.to_le_bytes());
    let mut payload = bytes[36..].to_vec();
    payload[flag - 36] = 2;
    let bytes = common::checkpoint_file(bytes, common::checkpoint_version(bytes), &payload);
    read(&write_checkpoint(name, &bytes)).unwrap_err()
}

/// A withdrawal in progress (format 11, the file `withdrawal.bin`) reads
/// back to the same rows, window, next row and wall time, the rows' mean
/// strains continuing from the loading's; a flag other than 0 or 1 is
/// refused by name.
#[test]
fn a_withdrawal_in_progress_reads_back() {
    use granbed_cli::bed::checkpoint::{WITHDRAWAL_FILE_NAME, WithdrawalProgress};
    use granbed_cli::bed::run::Window;
    let (dir, _) = base_checkpoint();
    let mut ck = read(dir).unwrap();
    let last = *ck.progress.samples.last().unwrap();
    let rows = withdrawal_rows(&last, 3);
    ck.progress.withdrawal = Some(WithdrawalProgress {
        turn_steps: last.steps,
        rows,
        window: Window {
            time: 2e-5,
            impulse: [1e-5, 2e-5, -3e-7],
            die_normal: 4e-6,
            pairs: 1e-3,
            walls: 2e-3,
            min_j: 0.75,
            max_speed: 0.125,
        },
        next_row: last.strain - 3.5e-4,
        wall_time_s: 1.5,
    });
    let d = common::fresh_dir("fuzz_files", "withdrawal_in_progress");
    std::fs::create_dir_all(&d).unwrap();
    ck.write_as(&d, WITHDRAWAL_FILE_NAME).unwrap();
    let back = Checkpoint::read_from(&d, WITHDRAWAL_FILE_NAME).unwrap();
    assert_eq!(back, ck);
    // The flag is the word after the unloading flag 0, where a file
    // without a withdrawal in progress ends.
    let bytes = std::fs::read(d.join(WITHDRAWAL_FILE_NAME)).unwrap();
    let (_, without) = base_checkpoint();
    let e = with_flag_2(&bytes, withdrawal_word(without), "withdrawal_progress_flag");
    assert!(e.contains("unknown withdrawal flag 2"), "{e}");
}

/// The payload property below only resumes the mutants that decode; this
/// proves that branch runs: the lowest mantissa bit of a float near the
/// payload's end (the state's numbers, 8-byte fields counted from the end)
/// is flipped under a valid checksum, the checkpoint decodes, and the bed
/// resumes from it and finishes.
#[test]
fn a_checkpoint_with_a_nudged_float_decodes_and_resumes() {
    let (_, bytes) = base_checkpoint();
    let payload = &bytes[36..];
    let resumed = (1..=64).find_map(|k| {
        let mut p = payload.to_vec();
        // Before the counters (a nudged counter only moves a cost figure)
        // and the unloading and withdrawal flags (the last two words).
        let at = p.len().checked_sub(16 + COUNTER_BYTES + 8 * k)?;
        p[at] ^= 1;
        let b = common::checkpoint_file(bytes, common::checkpoint_version(bytes), &p);
        let dir = write_checkpoint("nudged", &b);
        read(&dir).ok()?;
        Some(common::cli(&[
            "bed",
            "--quiet",
            "--resume",
            dir.to_str().unwrap(),
            "--strain",
            "0.01",
            "--stop-at-strain",
            "0.0051",
        ]))
    });
    let run = resumed.expect("no nudged checkpoint decoded: the property's resume branch is dead");
    assert_eq!(run.code, 0, "{}", run.stderr);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(300)))]

    #[test]
    fn corrupted_checkpoints_are_refused(edits in proptest::collection::vec(edit(), 1..4)) {
        let (_, bytes) = base_checkpoint();
        let mut b = bytes.clone();
        apply(&mut b, &edits);
        prop_assume!(&b != bytes);
        let dir = write_checkpoint("corrupted", &b);
        // The checksum (or the header) catches every change.
        prop_assert!(read(&dir).is_err());
    }

    #[test]
    fn mutated_payloads_with_a_valid_checksum_decode_or_fail_cleanly(
        edits in proptest::collection::vec(edit(), 1..6),
    ) {
        let (_, bytes) = base_checkpoint();
        let mut payload = bytes[36..].to_vec();
        apply(&mut payload, &edits);
        let b = common::checkpoint_file(bytes, common::checkpoint_version(bytes), &payload);
        let dir = write_checkpoint("payload", &b);
        if read(&dir).is_ok() {
            // It decoded: resuming must accept it or refuse it with an
            // error (exit status 1 or 2), never panic. The run stops just
            // past the checkpoint's strain (0.005).
            let run = common::cli(&[
                "bed",
                "--quiet",
                "--resume",
                dir.to_str().unwrap(),
                "--strain",
                "0.01",
                "--stop-at-strain",
                "0.0051",
            ]);
            prop_assert!(run.code <= 2, "exit {}: {}", run.code, run.stderr);
        }
    }
}
