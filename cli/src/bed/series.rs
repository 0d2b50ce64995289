//! A series of bed runs (`--types`, `--seeds`) kept resumable as a whole.
//!
//! A series writes `DIR/series.json` ([`SeriesFile`]) before its first
//! run: what kind of series it is, its members in order, the scene they
//! share and, for `--types`, the one pour they all compress (sphere
//! centres as their bits, so a member started later gets the same bed).
//! `granbed-cli bed --resume DIR` on such a directory then continues every
//! member from its checkpoint, runs the members never started from the
//! series' scene (and pour), refits the finished ones with the windows
//! given, and writes `DIR`'s tables again — what an interrupted series
//! had left unwritten, or a refit would otherwise leave stale.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use granbed_kernel::material::GranuleType;
use serde::{Deserialize, Serialize};

use super::seeds::seed_dir;
use super::{
    BedArgs, Scene, SeriesRun, checkpoint, compare, outputs, plots, report, run, seeds, snapshots,
};
use crate::error::input_error;
use crate::output::Streams;

/// File name of the series description in the series directory.
pub const FILE_NAME: &str = "series.json";
/// Format version written and read.
pub const FORMAT: u32 = 1;

/// What a series runs once per member.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SeriesKind {
    /// `--types`: one granule type per member, all from one pour.
    Types,
    /// `--seeds`: one seed per member, each with its own pour.
    Seeds,
}

/// The pour a `--types` series shares, exactly: floats as their bits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredPacking {
    /// The granule type whose sphere density the pour used.
    pub granule_type: String,
    /// Sphere centres, m, as `f64::to_bits`.
    pub centres_bits: Vec<[u64; 3]>,
    /// Sphere radius, m, as bits.
    pub radius_m_bits: u64,
    /// Die radius, m, as bits.
    pub die_radius_m_bits: u64,
    /// Wall time of the pour, s.
    pub wall_time_s: f64,
}

impl StoredPacking {
    /// `packing`, poured with the sphere density of `granule_type`.
    pub fn new(granule_type: GranuleType, packing: &run::Packing) -> Self {
        Self {
            granule_type: granule_type.name().to_owned(),
            centres_bits: packing
                .centres
                .iter()
                .map(|c| c.map(f64::to_bits))
                .collect(),
            radius_m_bits: packing.radius_m.to_bits(),
            die_radius_m_bits: packing.die_radius_m.to_bits(),
            wall_time_s: packing.wall_time_s,
        }
    }

    /// The packing, bit for bit as stored.
    pub fn packing(&self) -> run::Packing {
        run::Packing {
            centres: self
                .centres_bits
                .iter()
                .map(|c| c.map(f64::from_bits))
                .collect(),
            radius_m: f64::from_bits(self.radius_m_bits),
            die_radius_m: f64::from_bits(self.die_radius_m_bits),
            wall_time_s: self.wall_time_s,
        }
    }
}

/// `DIR/series.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeriesFile {
    /// [`FORMAT`].
    pub format: u32,
    /// The kind of series.
    pub kind: SeriesKind,
    /// The members in order: granule type names, or seeds in decimal.
    pub members: Vec<String>,
    /// The scene every member starts from (TOML), before its own type or
    /// seed is set.
    pub scene_toml: String,
    /// The shared pour (`--types` only).
    pub pour: Option<StoredPacking>,
}

/// One member of a series: its name in messages, its label on the
/// progress bar, its directory and its scene when started afresh. The one
/// place a fresh series and its resume both take them from.
pub(super) struct Member {
    pub(super) name: String,
    pub(super) label: String,
    pub(super) dir: PathBuf,
    pub(super) scene: Scene,
}

impl Member {
    /// Granule type `t` of a `--types` series in `dir` on the scene `base`.
    pub(super) fn of_type(dir: &Path, t: GranuleType, base: &Scene) -> Self {
        Self {
            name: format!("granule type {t}"),
            label: format!("bed {t}"),
            dir: dir.join(t.name()),
            scene: Scene {
                granule_type: t.name().to_owned(),
                ..base.clone()
            },
        }
    }

    /// Seed `seed` of a `--seeds` series in `dir` on the scene `base`.
    pub(super) fn of_seed(dir: &Path, seed: u64, base: &Scene) -> Self {
        Self {
            name: format!("seed {seed}"),
            label: format!("bed seed {seed}"),
            dir: dir.join(seed_dir(seed)),
            scene: Scene {
                seed,
                ..base.clone()
            },
        }
    }

    /// The member's run on `scene` (its own, or as a resume overrides it),
    /// from `packing` or the checkpoint `resume`.
    pub(super) fn run<'a>(
        &self,
        scene: &'a Scene,
        packing: Option<run::Packing>,
        resume: Option<checkpoint::Checkpoint>,
    ) -> SeriesRun<'a> {
        SeriesRun {
            name: self.name.clone(),
            label: self.label.clone(),
            dir: self.dir.clone(),
            scene,
            packing,
            resume,
        }
    }

    /// `Err` unless the checkpoint `c` in the member's directory is a run
    /// of the member: the same granule type, seed, bed and material as its
    /// fresh scene (the fields `--resume` may change aside).
    fn check_checkpoint(&self, c: &checkpoint::Checkpoint) -> anyhow::Result<()> {
        let ran = Scene::from_toml(&c.progress.scene_toml)
            .with_context(|| format!("{}: the checkpoint's scene", self.name))?;
        let fresh = &self.scene;
        let same = ran.granule_type == fresh.granule_type
            && ran.seed == fresh.seed
            && ran.granules == fresh.granules
            && ran.mesh == fresh.mesh
            && ran.diameter_mm.to_bits() == fresh.diameter_mm.to_bits()
            && ran.die_diameter_mm.to_bits() == fresh.die_diameter_mm.to_bits()
            && ran.punch_speed_m_s.to_bits() == fresh.punch_speed_m_s.to_bits()
            && ran.material == fresh.material;
        if same {
            return Ok(());
        }
        Err(input_error(format!(
            "{}: the checkpoint in `{}` is not a run of this series (another granule type, seed, \
             bed or material than its series.json): remove that directory to run the member \
             afresh, or resume it alone with --resume {}",
            self.name,
            self.dir.display(),
            self.dir.display()
        )))
    }
}

impl SeriesFile {
    /// Whether `dir` holds a series description.
    pub fn is_in(dir: &Path) -> bool {
        dir.join(FILE_NAME).is_file()
    }

    /// Writes the file into `dir` atomically (a temporary file, synced,
    /// renamed over the old one).
    pub fn write(&self, dir: &Path) -> anyhow::Result<()> {
        let path = dir.join(FILE_NAME);
        let tmp = dir.join(format!("{FILE_NAME}.tmp"));
        let ctx = || format!("cannot write `{}`", tmp.display());
        let mut text = serde_json::to_vec_pretty(self).with_context(ctx)?;
        text.push(b'\n');
        let mut file = std::fs::File::create(&tmp).with_context(ctx)?;
        file.write_all(&text)
            .and_then(|()| file.sync_all())
            .with_context(ctx)?;
        drop(file);
        std::fs::rename(&tmp, &path)
            .with_context(|| format!("cannot move the series file to `{}`", path.display()))
    }

    /// Reads `dir/series.json`; an error names the file and what is wrong
    /// with it.
    pub fn read(dir: &Path) -> anyhow::Result<Self> {
        let path = dir.join(FILE_NAME);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read `{}`", path.display()))?;
        let bad = |what: String| input_error(format!("`{}`: {what}", path.display()));
        let file: Self = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if file.format != FORMAT {
            return Err(bad(format!(
                "format {} (this build reads format {FORMAT})",
                file.format
            )));
        }
        if file.members.is_empty() {
            return Err(bad("no members".to_owned()));
        }
        if (file.kind == SeriesKind::Types) != file.pour.is_some() {
            return Err(bad(
                "a series of types holds its pour, a series of seeds none".to_owned(),
            ));
        }
        if let Some(pour) = &file.pour {
            pour.granule_type.parse::<GranuleType>().map_err(|_| {
                bad(format!(
                    "the pour's granule type `{}` is none of A1 ... C3",
                    pour.granule_type
                ))
            })?;
        }
        Ok(file)
    }

    /// The members with their directories in `dir` and their fresh
    /// scenes; an error names a member that is no type or seed.
    fn members(&self, dir: &Path) -> anyhow::Result<Vec<Member>> {
        let base = Scene::from_toml(&self.scene_toml).context("the series' scene")?;
        self.members
            .iter()
            .map(|m| {
                let bad =
                    || input_error(format!("`{}`: member `{m}`", dir.join(FILE_NAME).display()));
                Ok(match self.kind {
                    SeriesKind::Types => Member::of_type(dir, m.parse().map_err(|_| bad())?, &base),
                    SeriesKind::Seeds => Member::of_seed(dir, m.parse().map_err(|_| bad())?, &base),
                })
            })
            .collect()
    }
}

/// The overrides of a scene's `[material]` that a `--types` series checks
/// ([`crate::material_args::check_type_overrides`]), named as the scene
/// spells them.
pub(super) fn type_overrides(scene: &Scene) -> [(Option<f64>, &'static str); 2] {
    [
        (
            scene.material.yield_stress_pa,
            "the scene's material.yield_stress_pa",
        ),
        (scene.material.eta0, "the scene's material.eta0"),
    ]
}

/// `Err` naming the runs in `dir`'s sub-directories when `dir` holds no
/// checkpoint and no [`FILE_NAME`] but runs of its own (a series written
/// before series files): each resumes alone. `Ok` otherwise.
pub fn refuse_runs_without_series(dir: &Path) -> anyhow::Result<()> {
    if dir.join(checkpoint::FILE_NAME).is_file() || SeriesFile::is_in(dir) {
        return Ok(());
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let mut runs: Vec<String> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().join(checkpoint::FILE_NAME).is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if runs.is_empty() {
        return Ok(());
    }
    runs.sort();
    Err(input_error(format!(
        "`{}` holds no checkpoint and no {FILE_NAME}, but runs with checkpoints in {}: resume \
         each alone with --resume {}/<run>",
        dir.display(),
        runs.join(", "),
        dir.display()
    )))
}

/// The outputs a single run writes into its directory (besides its
/// snapshots, [`snapshots::remove_old`]).
fn single_run_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = vec![
        dir.join(checkpoint::FILE_NAME),
        dir.join(outputs::COMPRESSION_CSV),
        dir.join(super::unloading::UNLOADING_CSV),
        dir.join(outputs::SUMMARY_JSON),
        dir.join(report::REPORT_FILE),
    ];
    files.extend(
        plots::PLOT_FILES
            .iter()
            .map(|f| dir.join(plots::PLOTS_DIR).join(f)),
    );
    files
}

/// The tables a series writes into its directory (both kinds), its
/// report (named as a single run's) and the series file.
fn series_files(dir: &Path) -> Vec<PathBuf> {
    [
        FILE_NAME,
        report::REPORT_FILE,
        compare::COMPARISON_CSV,
        compare::COMPARISON_JSON,
        compare::PRESSURE_SVG,
        compare::DENSITY_SVG,
        compare::PROFILE_SVG,
        seeds::SEEDS_CSV,
        seeds::SPREAD_CSV,
        seeds::SEEDS_JSON,
    ]
    .iter()
    .chain(&seeds::SEEDS_SVG)
    .map(|f| dir.join(f))
    .collect()
}

/// Removes the `files` that exist; an error names the file.
fn remove_files(files: &[PathBuf]) -> anyhow::Result<()> {
    for f in files.iter().filter(|f| f.is_file()) {
        std::fs::remove_file(f).with_context(|| format!("cannot remove `{}`", f.display()))?;
    }
    Ok(())
}

/// Before a fresh run of `kind` into `dir` (a series, or a single run when
/// `series` is false): outputs of the other kind there would mix with the
/// new ones, and `--resume DIR` would take the wrong one (a run's
/// checkpoint before a series file). Refused, naming what is there; with
/// `overwrite` the other kind's files in `dir` are removed (a series'
/// member directories are left).
pub fn clear_other_kind(dir: &Path, series: bool, overwrite: bool) -> anyhow::Result<()> {
    let (found, files) = if series {
        (
            dir.join(outputs::SUMMARY_JSON).is_file() || dir.join(checkpoint::FILE_NAME).is_file(),
            single_run_files(dir),
        )
    } else {
        (SeriesFile::is_in(dir), series_files(dir))
    };
    if !found {
        return Ok(());
    }
    if overwrite {
        remove_files(&files)?;
        if series {
            snapshots::remove_old(dir)?;
        }
        return Ok(());
    }
    let (there, new) = if series {
        (
            "a single run (its summary.json or checkpoint.bin)",
            "a series",
        )
    } else {
        ("a series (its series.json)", "a single run")
    };
    Err(input_error(format!(
        "`{}` holds {there}: {new} there would mix its files with it; choose another --out, or \
         pass --overwrite to remove that run's files from `{}` first",
        dir.display(),
        dir.display()
    )))
}

/// Before a fresh series into `dir` with its `members`' directories, once
/// everything is validated: a single run's files in `dir` refused (or, with
/// `overwrite`, removed: [`clear_other_kind`]); an earlier series' tables
/// (either kind) removed, as a finished run is replaced; and each member's
/// old checkpoint removed (finished — an unfinished one was refused
/// without `overwrite`), so that a resume of the new series never takes an
/// earlier run for one of its members.
pub fn prepare_fresh(dir: &Path, members: &[PathBuf], overwrite: bool) -> anyhow::Result<()> {
    clear_other_kind(dir, true, overwrite)?;
    remove_files(&series_files(dir))?;
    let checkpoints: Vec<PathBuf> = members
        .iter()
        .map(|m| m.join(checkpoint::FILE_NAME))
        .collect();
    remove_files(&checkpoints)
}

impl BedArgs {
    /// `--print-scene --resume DIR` on a series directory: the series'
    /// scene with the overrides given (each member sets its own type or
    /// seed).
    pub(super) fn print_series_scene(
        &self,
        dir: &Path,
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<()> {
        let file = SeriesFile::read(dir)?;
        let base = Scene::from_toml(&file.scene_toml).context("the series' scene")?;
        write!(
            streams.stdout,
            "{}",
            self.overridden(base, false)?.to_toml()
        )?;
        Ok(())
    }

    /// `--resume DIR` on a series directory: every member continued from
    /// its checkpoint (with the overrides allowed with `--resume`), or
    /// started afresh from the series' scene and pour if it has none; then
    /// the series' tables written again.
    pub(super) fn resume_series(
        &self,
        dir: &Path,
        pool: &rayon::ThreadPool,
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<()> {
        for (given, flag) in [
            (self.stop_at_strain.is_some(), "--stop-at-strain"),
            (self.rate_check, "--rate-check"),
        ] {
            if given {
                return Err(input_error(format!(
                    "`{flag}` is not taken when resuming the series in `{}`; resume one of its \
                     runs alone with --resume on its directory",
                    dir.display()
                )));
            }
        }
        let file = SeriesFile::read(dir)?;
        let packing = file.pour.as_ref().map(StoredPacking::packing);
        // Every member's scene is made and checked before anything runs.
        let mut scenes = Vec::new();
        let mut resumes = Vec::new();
        let members = file.members(dir)?;
        for m in &members {
            let resume = if m.dir.join(checkpoint::FILE_NAME).is_file() {
                let c = checkpoint::Checkpoint::read(&m.dir).with_context(|| m.name.clone())?;
                m.check_checkpoint(&c)?;
                Some(c)
            } else {
                None
            };
            let scene = match &resume {
                Some(c) => self.scene(Some(c)),
                None => self.overridden(m.scene.clone(), true),
            }
            .with_context(|| m.name.clone())?;
            scenes.push(scene);
            resumes.push(resume);
        }
        if !self.quiet {
            let started = resumes.iter().filter(|r| r.is_some()).count();
            writeln!(
                streams.stderr,
                "bed: resuming the series in `{}`: {} runs, {started} with a checkpoint",
                dir.display(),
                members.len()
            )?;
        }
        let mut series: Vec<SeriesRun> = members
            .iter()
            .zip(&scenes)
            .zip(resumes)
            .map(|((m, scene), resume)| m.run(scene, packing.clone(), resume))
            .collect();
        let what = match file.kind {
            SeriesKind::Types => "comparison",
            SeriesKind::Seeds => "spread",
        };
        // The warning a fresh --types gave about the scene's material
        // overrides, again in the summaries written anew.
        let mut notes = Vec::new();
        if file.kind == SeriesKind::Types {
            let types: Vec<GranuleType> = scenes
                .iter()
                .map(Scene::granule_type)
                .collect::<anyhow::Result<_>>()?;
            let given = type_overrides(&members[0].scene);
            if let Some(w) = crate::material_args::check_type_overrides(&types, given)? {
                notes.push(w);
            }
        }
        let runs = self.compress_series(pool, &mut series, dir, what, &notes, streams)?;
        match &file.pour {
            Some(pour) => {
                let pour_type: GranuleType = pour.granule_type.parse()?;
                super::write_types_tables(dir, &scenes, &runs, pour_type, pour.wall_time_s)?;
            }
            None => super::seeds::write_seed_tables(dir, &scenes, &runs)?,
        }
        super::series_failures(&series, runs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh series clears its members' old checkpoints and an earlier
    /// series' tables, refuses a single run's files without `overwrite`
    /// (removing nothing) and removes them with it.
    #[test]
    fn a_fresh_series_clears_what_a_resume_could_mistake() {
        let dir = std::env::temp_dir().join(format!("granbed-series-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let member = dir.join("A1");
        std::fs::create_dir_all(&member).unwrap();
        let members = [member.clone()];
        let touch = |p: &Path| std::fs::write(p, b"x").unwrap();
        touch(&member.join(checkpoint::FILE_NAME));
        touch(&member.join(outputs::SUMMARY_JSON));
        touch(&dir.join(seeds::SEEDS_CSV));
        touch(&dir.join(FILE_NAME));
        prepare_fresh(&dir, &members, false).unwrap();
        assert!(!member.join(checkpoint::FILE_NAME).exists());
        assert!(
            member.join(outputs::SUMMARY_JSON).exists(),
            "a member's outputs are its own"
        );
        assert!(!dir.join(seeds::SEEDS_CSV).exists() && !SeriesFile::is_in(&dir));

        touch(&dir.join(outputs::SUMMARY_JSON));
        touch(&member.join(checkpoint::FILE_NAME));
        let e = prepare_fresh(&dir, &members, false).unwrap_err();
        assert!(e.to_string().contains("holds a single run"), "{e}");
        assert!(
            member.join(checkpoint::FILE_NAME).exists(),
            "a refusal removed a file"
        );
        prepare_fresh(&dir, &members, true).unwrap();
        assert!(!dir.join(outputs::SUMMARY_JSON).exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
