//! The stability suite (issue #9): every granule type compressed far past
//! where the published runs broke down (30 %), in beds poured from several
//! seeds to 60 % axial strain and as single granules between platens to
//! 70 %, with what each run did to the numerics recorded and judged.
//!
//! Per run: the smallest element Jacobian ratio over the run (at the
//! element centres every step, and at the 2×2×2 Gauss points at the output
//! rows: an hourglass-distorted hex folds there first), the largest
//! nodal speed over the punch (platen) speed, the deepest granule–granule
//! (granule–platen) overlap at the output rows over the element size (the
//! shortest surface edge of the reference mesh) as the contact detection
//! reports it, the deepest overlap measured by geometry alone at every
//! [`PROBE_INTERVAL`] of strain (beds; [`Assembly::hidden_overlap`]: the
//! winding number of each neighbour's closed surface, which shares none of
//! the detection's choices and so catches what it misses), the
//! energy-ledger residual
//! over the punch (platen) work, the hourglass energy over the internal
//! work, the error that stopped the run if any, and the wall time.
//!
//! A run passes when it reaches its strain without an error, no element
//! inverted or folded (both Jacobians > 0), the residual is below 1 % of the punch work
//! and both overlaps below 1 % of the element size. granbed neither rejects
//! nor repairs steps: a step that fails stops the run (with a checkpoint in
//! `bed`), so "rejected or repaired steps" is 0 for every run that passes
//! and the error column says what stopped one that did not.

use std::time::Instant;

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::material::GranuleType;
use granbed_kernel::scene::platens::{PlatenParams, PlatenSample};

use super::StabilityArgs;
use crate::assembly::Assembly;
use crate::assembly::overlap::Overlap;
use crate::bed::outputs::summary;
use crate::bed::run::{BedObserver, BedRun, BedSample, RunControl, run_bed};
use crate::bed::scene::Scene;
use crate::csv::{CsvWriter, Field};
use crate::granule::GRANULE_RADIUS_M;
use crate::granule::run::run_platens;
use crate::model::{MeshLevel, OwnedReference};
use crate::output::{Streams, create_file, finish_file, finite_ratio, write_json, write_text};
use crate::plot::{Mark, Series, xy_svg};

/// The table of the suite.
pub const CSV_FILE: &str = "stability.csv";
/// The table as JSON, with the settings.
pub const JSON_FILE: &str = "stability.json";
/// Plots: per type, the worst of its beds against the axial strain.
pub const PLOT_FILES: [&str; 4] = [
    "min_jacobian_beds.svg",
    "penetration_beds.svg",
    "node_speed_beds.svg",
    "min_jacobian_granules.svg",
];

/// Largest energy residual / punch work of a passing run.
pub const MAX_RESIDUAL_REL: Real = 0.01;
/// Largest overlap / element size of a passing run (either measure).
pub const MAX_PENETRATION_REL: Real = 0.01;

/// Strain between two probes of a bed's overlap by geometry
/// ([`Assembly::hidden_overlap`]), the first at this strain: the hidden
/// overlaps of session 43 began at C = 0.445–0.595 and stayed.
pub const PROBE_INTERVAL: Real = 0.05;

/// Columns of [`CSV_FILE`].
pub const COLUMNS: [&str; 17] = [
    "kind",
    "type",
    "seed",
    "target_strain",
    "final_strain",
    "steps",
    "min_jacobian",
    "min_gauss_jacobian",
    "max_node_speed_ratio",
    "max_penetration_rel_element",
    "max_hidden_overlap_rel_element",
    "energy_residual_rel",
    "hourglass_to_internal",
    "rejected_steps",
    "wall_time_s",
    "stopped_early",
    "passed",
];

/// What one run of the suite measured.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Record {
    /// `bed` or `granule`.
    pub kind: &'static str,
    /// Granule type.
    pub granule_type: &'static str,
    /// Seed of the pour (beds; 0 for granules).
    pub seed: u64,
    /// Strain the run was asked to reach.
    pub target_strain: Real,
    /// Strain it reached.
    pub final_strain: Real,
    /// Steps.
    pub steps: u64,
    /// Smallest element-centre Jacobian ratio (every step).
    pub min_jacobian: Real,
    /// Smallest Gauss-point Jacobian ratio (at the output rows): a folded
    /// element shows here first.
    pub min_gauss_jacobian: Real,
    /// Largest nodal speed / punch (platen) speed.
    pub max_node_speed_ratio: Option<Real>,
    /// Deepest overlap / element size, as the contact detection reports it.
    pub max_penetration_rel_element: Option<Real>,
    /// Deepest overlap / element size measured by geometry alone at the
    /// probes (beds; `None` for granules, whose platens are planes the
    /// detection cannot miss).
    pub max_hidden_overlap_rel_element: Option<Real>,
    /// |energy residual| / punch (platen) work.
    pub energy_residual_rel: Option<Real>,
    /// Hourglass energy / internal work at the end.
    pub hourglass_to_internal: Option<Real>,
    /// Steps rejected or repaired (granbed has no such mechanism: always 0).
    pub rejected_steps: u64,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// The error that stopped the run, if any.
    pub error: Option<String>,
    /// Whether the run meets every criterion.
    pub passed: bool,
}

impl Record {
    /// Judges the measured values (see the module documentation).
    fn judge(mut self) -> Self {
        self.passed = self.error.is_none()
            && self.final_strain + 1e-9 >= self.target_strain
            && self.min_jacobian > 0.0
            && self.min_gauss_jacobian > 0.0
            && self
                .energy_residual_rel
                .is_some_and(|r| r < MAX_RESIDUAL_REL)
            && self
                .max_penetration_rel_element
                .is_some_and(|r| r < MAX_PENETRATION_REL)
            && (self.kind != "bed"
                || self
                    .max_hidden_overlap_rel_element
                    .is_some_and(|r| r < MAX_PENETRATION_REL));
        self
    }

    fn row(&self) -> [Field; 17] {
        let opt = |x: Option<Real>| Field::Real(x.unwrap_or(Real::NAN));
        [
            Field::Text(self.kind),
            Field::Text(self.granule_type),
            Field::Int(self.seed),
            self.target_strain.into(),
            self.final_strain.into(),
            Field::Int(self.steps),
            self.min_jacobian.into(),
            self.min_gauss_jacobian.into(),
            opt(self.max_node_speed_ratio),
            opt(self.max_penetration_rel_element),
            opt(self.max_hidden_overlap_rel_element),
            opt(self.energy_residual_rel),
            opt(self.hourglass_to_internal),
            Field::Int(self.rejected_steps),
            self.wall_time_s.into(),
            self.error.is_some().into(),
            self.passed.into(),
        ]
    }
}

/// A bed run's observer that keeps nothing (the samples come back in the
/// [`BedRun`]).
pub(crate) struct Silent;

impl BedObserver for Silent {
    fn sample(&mut self, _: &BedSample, _: f64) {}

    fn snapshot(
        &mut self,
        _: Real,
        _: &crate::assembly::Assembly<'_>,
        _: &OwnedReference,
    ) -> anyhow::Result<()> {
        Ok(())
    }
}

/// A bed run's observer that measures the overlap by geometry
/// ([`Assembly::hidden_overlap`]) at every snapshot and keeps the deepest.
#[derive(Default)]
pub(crate) struct OverlapProbe {
    /// The deepest found so far (the first NaN, once there is one).
    pub deepest: Overlap,
    /// Probes taken.
    pub probes: usize,
}

impl BedObserver for OverlapProbe {
    fn sample(&mut self, _: &BedSample, _: f64) {}

    fn snapshot(&mut self, _: Real, asm: &Assembly<'_>, _: &OwnedReference) -> anyhow::Result<()> {
        self.deepest = self.deepest.deeper(asm.hidden_overlap());
        self.probes += 1;
        Ok(())
    }
}

/// The strains at which the suite probes a bed's overlap: every
/// [`PROBE_INTERVAL`] up to `final_strain`, and `final_strain` itself.
pub fn probe_strains(final_strain: Real) -> Vec<Real> {
    let mut strains: Vec<Real> = (1..)
        .map(|k| k as Real * PROBE_INTERVAL)
        .take_while(|&c| c < final_strain - 1e-9)
        .collect();
    strains.push(final_strain);
    strains
}

/// The bed scene of the suite for `granule_type` and `seed`.
pub fn bed_scene(args: &StabilityArgs, granule_type: GranuleType, seed: u64) -> Scene {
    let published = Scene::published();
    Scene {
        contact_sweeps: args.contact_sweeps.unwrap_or(published.contact_sweeps),
        sweep_tolerance: args.sweep_tolerance.unwrap_or(published.sweep_tolerance),
        mass_scaling: args.mass_scaling.unwrap_or(published.mass_scaling),
        time_step_floor: args.time_step_floor.unwrap_or(published.time_step_floor),
        nearest_penetrated_face: args
            .nearest_penetrated_face
            .unwrap_or(published.nearest_penetrated_face),
        watchdog_speed_ratio: args
            .watchdog_speed_ratio
            .unwrap_or(published.watchdog_speed_ratio),
        granule_type: granule_type.name().to_string(),
        granules: args.granules,
        mesh: args.mesh.to_string(),
        seed,
        die_diameter_mm: args.die_diameter_mm,
        final_strain: args.strain,
        snapshot_strains: Vec::new(),
        // The suite judges the loading.
        unload: false,
        ..published
    }
}

/// Runs one bed of the suite; its samples are returned for the plots.
pub fn run_bed_case(scene: &Scene) -> anyhow::Result<(Record, BedRun)> {
    // The probes of the overlap by geometry ([`OverlapProbe`]) are taken
    // at the snapshots, which change nothing else in a run.
    let probed = Scene {
        snapshot_strains: probe_strains(scene.final_strain),
        ..scene.clone()
    };
    let mut probe = OverlapProbe::default();
    let run = run_bed(&probed, &RunControl::default(), &mut probe)?;
    let s = summary(scene, &run);
    let element = scene.granule_mesh()?.shortest_surface_edge();
    let record = Record {
        kind: "bed",
        granule_type: scene.granule_type()?.name(),
        seed: scene.seed,
        target_strain: scene.final_strain,
        final_strain: s.final_strain,
        steps: run.steps,
        min_jacobian: s.min_jacobian,
        min_gauss_jacobian: s.min_gauss_jacobian,
        max_node_speed_ratio: s.max_node_speed_ratio,
        max_penetration_rel_element: s.max_penetration_rel_element,
        max_hidden_overlap_rel_element: if probe.probes == 0 {
            None
        } else {
            finite_ratio(probe.deepest.depth_m, element)
        },
        energy_residual_rel: s.energy_residual_rel,
        hourglass_to_internal: s.hourglass_to_internal,
        rejected_steps: 0,
        wall_time_s: run.wall_time_s,
        error: s.error,
        passed: false,
    }
    .judge();
    Ok((record, run))
}

/// Runs one granule of `granule_type` between platens (octant, the
/// `granule` command's defaults) to `strain` on `mesh`.
pub fn run_granule_case(
    granule_type: GranuleType,
    mesh: MeshLevel,
    strain: Real,
) -> anyhow::Result<(Record, Vec<PlatenSample>)> {
    let material = granule_type
        .params()
        .validate()
        .context("preset material")?;
    let reference = OwnedReference::sphere(GRANULE_RADIUS_M, mesh, true)?;
    let mut params = PlatenParams::standard(material);
    params.final_strain = strain;
    let start = Instant::now();
    let result = run_platens(params, &reference, &mut |_, _| {}).map_err(anyhow::Error::new)?;
    let wall_time_s = start.elapsed().as_secs_f64();
    let samples = result.samples;
    let last = samples.last().copied();
    let e = last.map(|s| s.energy).unwrap_or_default();
    let fold = |f: fn(&PlatenSample) -> Real, start: Real, pick: fn(Real, Real) -> Real| {
        samples.iter().map(f).fold(start, pick)
    };
    let min_jacobian = fold(|s| s.min_j, Real::INFINITY, Real::min);
    let min_gauss_jacobian = fold(|s| s.min_gauss_jacobian, Real::INFINITY, Real::min);
    let max_speed = fold(|s| s.max_node_speed_m_s, 0.0, Real::max);
    let penetration = fold(|s| s.penetration_m, 0.0, Real::max);
    let record = Record {
        kind: "granule",
        granule_type: granule_type.name(),
        seed: 0,
        target_strain: strain,
        final_strain: last.map_or(0.0, |s| s.strain),
        steps: result.steps,
        min_jacobian,
        min_gauss_jacobian,
        // The platens approach at `approach_speed_m_s`; each moves at half.
        max_node_speed_ratio: finite_ratio(max_speed, 0.5 * params.approach_speed_m_s),
        max_penetration_rel_element: finite_ratio(penetration, reference.shortest_surface_edge()),
        max_hidden_overlap_rel_element: None,
        energy_residual_rel: finite_ratio(e.residual().abs(), e.platen_work),
        hourglass_to_internal: finite_ratio(e.hourglass, e.internal_work),
        rejected_steps: 0,
        wall_time_s,
        error: result.error.map(|e| e.to_string()),
        passed: false,
    }
    .judge();
    Ok((record, samples))
}

/// Per sample index, the worst of `runs`' values `y` (the smallest when
/// `lowest`, else the largest), against the first run's strains.
fn worst(runs: &[&BedRun], y: fn(&BedSample) -> Real, lowest: bool) -> Vec<(Real, Real)> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    first
        .samples
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let values = runs.iter().filter_map(|r| r.samples.get(i)).map(y);
            let v = if lowest {
                values.fold(Real::INFINITY, Real::min)
            } else {
                values.fold(Real::NEG_INFINITY, Real::max)
            };
            (s.strain, v)
        })
        .collect()
}

/// The settings and rows of [`JSON_FILE`].
#[derive(serde::Serialize)]
struct Report<'a> {
    granules: usize,
    mesh: String,
    die_diameter_mm: Real,
    bed_strain: Real,
    beds_per_type: u64,
    /// The beds' numerical settings as run (the published scene's unless
    /// overridden).
    contact_sweeps: u32,
    sweep_tolerance: Real,
    mass_scaling: Real,
    time_step_floor: Real,
    watchdog_speed_ratio: Real,
    exact_contact_from_strain: Real,
    granule_mesh: String,
    granule_strain: Real,
    max_residual_rel: Real,
    max_penetration_rel: Real,
    all_passed: bool,
    runs: &'a [Record],
}

/// The largest platen strain of a single granule (the kernel's).
pub const MAX_GRANULE_STRAIN: Real = granbed_kernel::scene::platens::MAX_FINAL_STRAIN;

impl StabilityArgs {
    /// The flags that set the beds' scene fields, with their values (for
    /// errors that name the flag: `crate::bed::flag_error`).
    fn scene_flags(&self) -> Vec<(&'static str, String)> {
        use crate::numbers::Shown;
        let mut given = vec![
            ("--granules", self.granules.shown()),
            ("--die-diameter-mm", self.die_diameter_mm.shown()),
            ("--strain", self.strain.shown()),
        ];
        let optional = [
            ("--watchdog-speed-ratio", self.watchdog_speed_ratio),
            ("--sweep-tolerance", self.sweep_tolerance),
            ("--mass-scaling", self.mass_scaling),
            ("--time-step-floor", self.time_step_floor),
        ];
        given.extend(
            optional
                .iter()
                .filter_map(|(f, v)| v.map(|v| (*f, v.shown()))),
        );
        if let Some(n) = self.contact_sweeps {
            given.push(("--contact-sweeps", n.shown()));
        }
        given
    }

    /// Checks every run's settings before anything runs: the single
    /// granules' strain and each type's bed scene, an error naming the flag.
    pub fn validate(&self) -> anyhow::Result<()> {
        if !(self.granule_strain > 0.0 && self.granule_strain <= MAX_GRANULE_STRAIN) {
            return Err(crate::error::input_error(format!(
                "`--granule-strain {}` is out of range (allowed: 0 < C <= {MAX_GRANULE_STRAIN})",
                crate::numbers::short(self.granule_strain)
            )));
        }
        let given = self.scene_flags();
        for &t in &self.types.0 {
            bed_scene(self, t, 1)
                .validate()
                .map_err(|e| crate::bed::flag_error(e, &given))
                .with_context(|| format!("the suite's bed scene of {t}"))?;
        }
        Ok(())
    }

    /// Runs the suite, writes the table and the plots, and fails (after
    /// writing them) if any run did not pass.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        self.validate()?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()?;
        crate::output::create_out_dir(&self.out)?;
        let types = self.types.0.clone();
        let mut records = Vec::new();
        let say = |r: &Record, streams: &mut Streams<'_>| -> anyhow::Result<()> {
            if !self.quiet {
                writeln!(
                    streams.stderr,
                    "stability: {} {} seed {}: C = {:.3}, min J {:.3}, overlap {:.2e} of h{}, \
                     residual {:.1e}, {:.1} s{}",
                    r.kind,
                    r.granule_type,
                    r.seed,
                    r.final_strain,
                    r.min_jacobian.min(r.min_gauss_jacobian),
                    r.max_penetration_rel_element.unwrap_or(Real::NAN),
                    if r.kind == "bed" {
                        format!(
                            " (by geometry {:.2e})",
                            r.max_hidden_overlap_rel_element.unwrap_or(Real::NAN)
                        )
                    } else {
                        String::new()
                    },
                    r.energy_residual_rel.unwrap_or(Real::NAN),
                    r.wall_time_s,
                    if r.passed { "" } else { "  FAILED" }
                )?;
            }
            Ok(())
        };
        // Beds: every type, every seed; kept per type for the plots.
        let mut bed_runs: Vec<(GranuleType, Vec<BedRun>)> = Vec::new();
        for &t in &types {
            let mut runs = Vec::new();
            for seed in 1..=self.beds {
                let scene = bed_scene(self, t, seed);
                scene.validate().context("the suite's bed scene")?;
                let (record, run) = pool
                    .install(|| run_bed_case(&scene))
                    .with_context(|| format!("bed {t} seed {seed}"))?;
                say(&record, streams)?;
                records.push(record);
                runs.push(run);
            }
            bed_runs.push((t, runs));
        }
        let mut granule_curves = Vec::new();
        for &t in &types {
            let (record, samples) = pool
                .install(|| run_granule_case(t, self.granule_mesh, self.granule_strain))
                .with_context(|| format!("granule {t}"))?;
            say(&record, streams)?;
            records.push(record);
            granule_curves.push(Series::new(
                t.name(),
                Mark::Line,
                samples.iter().map(|s| (s.strain, s.min_gauss_jacobian)),
            ));
        }

        let path = self.out.join(CSV_FILE);
        let mut csv = CsvWriter::new(create_file(&path)?, &COLUMNS)
            .with_context(|| format!("cannot write to `{}`", path.display()))?;
        for r in &records {
            csv.write_row(&r.row())
                .with_context(|| format!("cannot write to `{}`", path.display()))?;
        }
        finish_file(csv.into_inner(), &path)?;
        let all_passed = records.iter().all(|r| r.passed);
        let beds = bed_scene(self, GranuleType::B2, 1);
        write_json(
            &self.out.join(JSON_FILE),
            &Report {
                granules: self.granules,
                mesh: self.mesh.to_string(),
                die_diameter_mm: self.die_diameter_mm,
                bed_strain: self.strain,
                beds_per_type: self.beds,
                contact_sweeps: beds.contact_sweeps,
                sweep_tolerance: beds.sweep_tolerance,
                mass_scaling: beds.mass_scaling,
                time_step_floor: beds.time_step_floor,
                watchdog_speed_ratio: beds.watchdog_speed_ratio,
                exact_contact_from_strain: beds.exact_contact_from_strain,
                granule_mesh: self.granule_mesh.to_string(),
                granule_strain: self.granule_strain,
                max_residual_rel: MAX_RESIDUAL_REL,
                max_penetration_rel: MAX_PENETRATION_REL,
                all_passed,
                runs: &records,
            },
        )?;
        let per_type = |y: fn(&BedSample) -> Real, lowest: bool| -> Vec<Series> {
            bed_runs
                .iter()
                .map(|(t, runs)| {
                    let refs: Vec<&BedRun> = runs.iter().collect();
                    Series::new(t.name(), Mark::Line, worst(&refs, y, lowest).into_iter())
                })
                .collect()
        };
        let strain = "axial strain C = (H0 - H)/H0";
        let beds = format!("worst of {} beds per type", self.beds);
        let plots = [
            xy_svg(
                &format!("Smallest Gauss-point Jacobian ratio ({beds})"),
                strain,
                "min J at the Gauss points",
                &per_type(|s| s.min_gauss_jacobian, true),
                true,
            )?,
            xy_svg(
                &format!("Deepest granule overlap ({beds})"),
                strain,
                "overlap, µm",
                &per_type(|s| 1e6 * s.penetration_m, false),
                true,
            )?,
            xy_svg(
                &format!("Largest nodal speed ({beds})"),
                strain,
                "max |v|, m/s",
                &per_type(|s| s.max_node_speed_m_s, false),
                true,
            )?,
            xy_svg(
                "Smallest Gauss-point Jacobian ratio, single granules",
                "platen strain x/d",
                "min J at the Gauss points",
                &granule_curves,
                true,
            )?,
        ];
        for (name, svg) in PLOT_FILES.iter().zip(&plots) {
            write_text(&self.out.join(name), svg)?;
        }
        let failed: Vec<String> = records
            .iter()
            .filter(|r| !r.passed)
            .map(|r| format!("{} {} seed {}", r.kind, r.granule_type, r.seed))
            .collect();
        if !failed.is_empty() {
            anyhow::bail!(
                "{} of {} runs failed the stability criteria: {} (see `{}`)",
                failed.len(),
                records.len(),
                failed.join(", "),
                self.out.join(CSV_FILE).display()
            );
        }
        if !self.quiet {
            writeln!(
                streams.stderr,
                "stability: all {} runs passed",
                records.len()
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The suite's options as `granbed-cli study stability` parses them.
    fn args(extra: &[&str]) -> StabilityArgs {
        #[derive(clap::Parser)]
        struct Wrapper {
            #[command(flatten)]
            args: StabilityArgs,
        }
        let argv = ["stability", "--out", "unused"].iter().chain(extra);
        <Wrapper as clap::Parser>::try_parse_from(argv)
            .unwrap()
            .args
    }

    /// The beds are the published scene unless overridden; the mass
    /// scaling and the sweep tolerance reach the scene.
    #[test]
    fn the_bed_overrides_reach_the_scene() {
        let published = Scene::published();
        let plain = bed_scene(&args(&[]), GranuleType::C3, 2);
        assert_eq!(plain.mass_scaling, published.mass_scaling);
        assert_eq!(plain.sweep_tolerance, published.sweep_tolerance);
        assert_eq!(plain.time_step_floor, published.time_step_floor);
        assert_eq!((plain.granule_type.as_str(), plain.seed), ("C3", 2));
        let changed = bed_scene(
            &args(&[
                "--mass-scaling",
                "30",
                "--sweep-tolerance",
                "0.02",
                "--time-step-floor",
                "0.9",
            ]),
            GranuleType::C3,
            2,
        );
        assert_eq!(
            (
                changed.mass_scaling,
                changed.sweep_tolerance,
                changed.time_step_floor
            ),
            (30.0, 0.02, 0.9)
        );
        assert_eq!(changed.selective_mass_ratio, published.selective_mass_ratio);
    }

    fn good() -> Record {
        Record {
            kind: "bed",
            granule_type: "B2",
            seed: 1,
            target_strain: 0.6,
            final_strain: 0.6,
            steps: 10,
            min_jacobian: 0.5,
            min_gauss_jacobian: 0.4,
            max_node_speed_ratio: Some(3.0),
            max_penetration_rel_element: Some(0.009),
            max_hidden_overlap_rel_element: Some(0.009),
            energy_residual_rel: Some(0.009),
            hourglass_to_internal: Some(0.1),
            rejected_steps: 0,
            wall_time_s: 1.0,
            error: None,
            passed: false,
        }
    }

    #[test]
    fn each_criterion_alone_fails_a_run() {
        assert!(good().judge().passed);
        let fails = [
            Record {
                error: Some("inverted".into()),
                ..good()
            },
            Record {
                final_strain: 0.59,
                ..good()
            },
            Record {
                min_jacobian: 0.0,
                ..good()
            },
            Record {
                min_jacobian: Real::NAN,
                ..good()
            },
            Record {
                min_gauss_jacobian: -0.1,
                ..good()
            },
            Record {
                energy_residual_rel: Some(0.01),
                ..good()
            },
            Record {
                energy_residual_rel: None,
                ..good()
            },
            Record {
                max_penetration_rel_element: Some(0.011),
                ..good()
            },
            Record {
                max_penetration_rel_element: None,
                ..good()
            },
            Record {
                max_hidden_overlap_rel_element: Some(0.011),
                ..good()
            },
            Record {
                max_hidden_overlap_rel_element: None,
                ..good()
            },
        ];
        // A granule between platens has no probe by geometry.
        assert!(
            Record {
                kind: "granule",
                max_hidden_overlap_rel_element: None,
                ..good()
            }
            .judge()
            .passed
        );
        for r in fails {
            let judged = r.clone().judge();
            assert!(!judged.passed, "{r:?} passed");
        }
    }

    #[test]
    fn the_worst_of_several_beds_is_taken_per_row() {
        let run = |j: [Real; 3]| {
            BedRun::of_samples(
                j.iter()
                    .enumerate()
                    .map(|(i, &min_jacobian)| BedSample {
                        strain: 0.1 * i as Real,
                        min_jacobian,
                        ..BedSample::default()
                    })
                    .collect(),
            )
        };
        let (a, b) = (run([1.0, 0.8, 0.9]), run([1.0, 0.9, 0.7]));
        let w = worst(&[&a, &b], |s| s.min_jacobian, true);
        assert_eq!(w, [(0.0, 1.0), (0.1, 0.8), (0.2, 0.7)]);
        let w = worst(&[&a, &b], |s| s.min_jacobian, false);
        assert_eq!(w, [(0.0, 1.0), (0.1, 0.9), (0.2, 0.9)]);
    }
}
