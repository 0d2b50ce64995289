//! `granbed-cli granule`: one granule compressed between two rigid platens
//! (the kernel's [`granbed_kernel::scene::platens`]), for one granule type
//! or several, with the force–displacement table, a summary with σ_est, and
//! a plot written to an output directory.
//!
//! * [`run`](mod@run): owned buffers and the loop over the kernel's scene;
//! * [`summary`]: σ_est, σ_y,eff0, energy checks, cost (`summary.json`);
//! * [`outputs`]: the CSV, JSON and text writers;
//! * [`plot`]: the SVG plots;
//! * [`progress`]: the progress bars on stderr.

use core::fmt;
use core::str::FromStr;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use clap::{Args, ValueEnum};
use granbed_kernel::Real;
use granbed_kernel::granule::forces::ElementKind;
use granbed_kernel::granule::timestep::TimeStepMethod;
use granbed_kernel::material::{GranuleType, Material};
use granbed_kernel::scene::platens::{PlatenParams, STANDARD_MASS_SCALING, SceneError, Symmetry};
use indicatif::MultiProgress;
use rayon::prelude::*;

use crate::error::InputError;
use crate::material_args::MaterialArgs;
use crate::model::{MeshLevel, OwnedReference};
use crate::output::Streams;

pub mod outputs;
pub mod plot;
pub mod progress;
pub mod report;
pub mod run;
pub mod section;
pub mod summary;

use run::RunResult;
use summary::{RunSetup, Summary, symmetry_name};

/// Radius of the simulated granule, m (the published 1 mm granule).
pub const GRANULE_RADIUS_M: Real = 0.5e-3;

/// The most steps a run may take (about 2·10⁴ times the standard run's
/// 47 096; at its pace, some six hours for the octant).
pub const MAX_STEPS: f64 = 1e9;

/// The slowest `--speed-mm-s`, mm/s (a fiftieth of the standard 5 mm/s):
/// the run's steps grow as 1/speed (at 10⁻⁶ mm/s about 10¹⁴ steps).
pub const MIN_SPEED_MM_S: f64 = 0.1;

/// The smallest `--output-strain` (the bed's floor,
/// [`crate::bed::scene::MIN_STRAIN_INTERVAL`]): every interval ends in a
/// sample the run keeps, so a smaller one would keep one every step.
pub const MIN_OUTPUT_STRAIN: f64 = crate::bed::scene::MIN_STRAIN_INTERVAL;
const _: () = assert!(MIN_OUTPUT_STRAIN == 1e-6, "spelled out in the message");

/// The granule diameters `--diameter-mm` accepts (`granule`,
/// `export-mesh`), mm: those of the browser calculator, 1 µm to 1 m.
pub const DIAMETER_RANGE_MM: [f64; 2] = [1.0e-3, 1.0e3];

/// The radius, m, of a granule of `--diameter-mm d`, or the usage error
/// naming the flag and [`DIAMETER_RANGE_MM`].
pub fn radius_of_diameter_mm(d: f64) -> anyhow::Result<Real> {
    let [lo, hi] = DIAMETER_RANGE_MM;
    if !(lo..=hi).contains(&d) {
        return Err(InputError(format!(
            "`--diameter-mm {}` is out of range (allowed: {lo} <= d <= {hi} mm)",
            crate::numbers::short(d)
        ))
        .into());
    }
    Ok(0.5e-3 * d)
}

/// Gravity of `--gravity`, m/s².
pub const GRAVITY_M_S2: Real = 9.81;

/// The output description shown at the end of `granule --help`.
const OUTPUT_HELP: &str = "\
Output, in --out DIR (created if missing; with --types in DIR/<TYPE>/ per type):
  force_displacement.csv  one row per sample: the unloaded state at t = 0, then
                          every --output-strain of platen approach:
    time_s                simulated time, s
    displacement_m        platen approach x (both platens together), m
    strain                x / d (d: --diameter-mm, 1 mm by default)
    force_n               mean of the upper and lower platen force, N
    force_upper_n         upper platen force, averaged over the sample interval, N
    force_lower_n         lower platen force (= upper in octant mode), N
    kinetic_j internal_work_j elastic_j plastic_j hourglass_j damping_j
    contact_work_j gravity_work_j platen_work_j
                          energy ledger of the whole granule, J
    min_jacobian          smallest element volume ratio J of the last step
    dt_s                  current time step, s
    steps                 time steps so far
  summary.json            every input, sigma_est (4/(pi d) dF/dx fitted over
                          strain 0.1 to 0.4; null with fewer than two samples
                          there), sigma_est_strain_range (the strains fitted:
                          less than 0.1-0.4 when the run ends before 0.4 or
                          --output-strain places no sample near 0.1, which
                          notes and stderr say), sigma_eff0, fit, energy checks, the
                          quasi-static certificate (kinetic/internal work over
                          the second half, with --symmetry full the platen force
                          imbalance, with --rate-check the change at half the
                          speed), cost, and \"error\" if the kernel stopped the
                          run
  force_displacement.svg  force against approach, with the sigma_est fit line
  section.svg             the final state cut through the centre (plane y = 0;
                          an octant mirrored), each hex coloured by its axial
                          stress -sigma_zz, between the platens (not written
                          for a run that failed)
  section_density.svg     the same section coloured by the local relative
                          density eta0/J
  energy_strain.svg       the energy ledger against x/d: where the platens'
                          work went
  report.html             one page: warnings, key results with units, the
                          plots, the pictures, every summary field with its
                          meaning and the CSV's columns
With --types, also in DIR: types.csv (one row per type: sigma_y, eta0,
sigma_eff0, sigma_est, the fit's slope and R^2, quasi_static_passed 1/0, steps,
wall time, energy residual, return-map gap), force_displacement_types.svg
(all types overlaid) and report.html (the types side by side, each linked to
its own report).
Floats are written round-trip exact. Progress bars go to stderr when it is a
terminal, then one summary line per type. If the kernel fails, the rows so far,
the summary (with its \"error\") and the plot are still written, and the error
names the type, step, strain and element. A run that fails the quasi-static
certificate says so on stderr (exit status 0: the outputs are complete).

Exit status: 0 success, 1 runtime failure (kernel or I/O error), 2 usage or
validation error.";

/// `--symmetry`: which part of the granule is simulated.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SymmetryArg {
    /// The positive octant with three symmetry planes (1/8 of the work);
    /// forces and energies are reported for the whole granule
    Octant,
    /// The whole granule between both platens
    Full,
}

/// `--element`: the element formulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ElementArg {
    /// One-point uniform-gradient hex with Flanagan–Belytschko hourglass
    /// stiffness (production element)
    OnePoint,
    /// 2×2×2 F-bar hex, mean dilatation, no hourglass control (verification
    /// element; about 8× the cost)
    Fbar,
}

/// `--time-step-method`: how the stable time step is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TimeStepArg {
    /// safety × 2/ω_max by power iteration every 1000 steps, tracked by the
    /// element lengths every 100 steps
    Global,
    /// safety × min element length / wave speed every 100 steps (1.3–2×
    /// more conservative)
    Element,
}

impl From<ElementArg> for ElementKind {
    fn from(e: ElementArg) -> Self {
        match e {
            ElementArg::OnePoint => Self::OnePoint,
            ElementArg::Fbar => Self::FBar,
        }
    }
}

impl From<SymmetryArg> for Symmetry {
    fn from(s: SymmetryArg) -> Self {
        match s {
            SymmetryArg::Octant => Self::Octant,
            SymmetryArg::Full => Self::Full,
        }
    }
}

/// `--types`: `all` or a comma list of distinct granule types.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TypeList(pub Vec<GranuleType>);

impl FromStr for TypeList {
    type Err = String;

    /// Parses `all` (A1…C3) or a comma list such as `A1,b2,C3`
    /// (case-insensitive, each type at most once).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim().eq_ignore_ascii_case("all") {
            return Ok(Self(GranuleType::ALL.to_vec()));
        }
        crate::numbers::distinct_list(s, |name| {
            if name.eq_ignore_ascii_case("all") {
                return Err("write `all` alone, not in a list".to_owned());
            }
            name.parse::<GranuleType>()
                .map_err(|e| format!("{e}, or `all` alone"))
        })
        .map(Self)
    }
}

impl fmt::Display for TypeList {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.0.iter().map(|t| t.name()).collect();
        f.write_str(&names.join(","))
    }
}

/// Options of `granbed-cli granule`.
#[derive(Args, Debug, Clone, PartialEq)]
#[command(after_long_help = OUTPUT_HELP)]
pub struct GranuleArgs {
    /// Output directory, created if missing; existing files of the same
    /// names are replaced.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Run several granule types instead of --type: `all` (A1…C3) or a
    /// comma list such as `A1,B2,C3`. The material overrides apply to every
    /// type: --yield-stress-pa or --eta0 leaving two listed types the same
    /// material is refused, replacing what they differ in is warned about.
    /// Writes `DIR/<TYPE>/…` per type plus `DIR/types.csv` and
    /// `DIR/force_displacement_types.svg`.
    #[arg(long, value_name = "LIST", conflicts_with = "granule_type")]
    pub types: Option<TypeList>,

    /// Mesh level NxM of the full sphere: n core divisions (even), m shell
    /// layers; 8x2 is the standard 1280-hex granule (160 hexes per octant),
    /// 4x1 the coarse 160-hex one.
    #[arg(long, default_value = "8x2")]
    pub mesh: MeshLevel,

    /// Granule diameter d, mm (0.001 ≤ d ≤ 1000). Strains are platen
    /// approach / d. A granule of k × d at the same platen speed in mm/s
    /// is the same experiment scaled (the same stresses at each strain,
    /// forces × k²) as long as there is no gravity.
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "MM",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub diameter_mm: f64,

    /// Simulated part of the granule.
    #[arg(long, value_enum, default_value_t = SymmetryArg::Octant)]
    pub symmetry: SymmetryArg,

    /// Element formulation.
    #[arg(long, value_enum, default_value_t = ElementArg::OnePoint)]
    pub element: ElementArg,

    /// Final strain: platen approach / granule diameter (0 < strain ≤ 0.9).
    #[arg(value_parser = crate::numbers::real, long, default_value_t = 0.4, allow_negative_numbers = true)]
    pub strain: f64,

    /// Speed at which the platens approach each other, mm/s
    /// (0.1 ≤ speed ≤ 10000); each platen moves at half of it.
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "MM_S",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    pub speed_mm_s: f64,

    /// Fraction ξ of critical damping of the granule's lowest
    /// deformational mode (0 ≤ ξ ≤ 2).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "XI",
        default_value_t = 0.5,
        allow_negative_numbers = true
    )]
    pub damping_ratio: f64,

    /// Hourglass stiffness coefficient κ of the one-point hexes
    /// (0 ≤ κ ≤ 1).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "KAPPA",
        default_value_t = 0.05,
        allow_negative_numbers = true
    )]
    pub hourglass_kappa: f64,

    /// Use the published return map literally, without the volume-drift fix.
    #[arg(long)]
    pub literal_return: bool,

    /// Strain between samples (CSV rows); the platen forces are averaged
    /// over each interval (10⁻⁶ ≤ interval ≤ --strain).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "STRAIN",
        default_value_t = 0.005,
        allow_negative_numbers = true
    )]
    pub output_strain: f64,

    /// How the stable time step is estimated.
    #[arg(long, value_enum, default_value_t = TimeStepArg::Global)]
    pub time_step_method: TimeStepArg,

    /// Safety factor C of the time-step estimate (0 < C ≤ 1).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "C",
        default_value_t = 0.9,
        allow_negative_numbers = true
    )]
    pub time_step_safety: f64,

    /// Apply gravity (9.81 m/s² in −z); only with `--symmetry full`.
    #[arg(long)]
    pub gravity: bool,

    /// Uniform mass scaling F (1 ≤ F ≤ 10⁶): masses ×F, gravity ÷F, so the
    /// stable step grows by √F. Check `quasi_static` in summary.json, and
    /// note that F > 1 raises σ_est of soft granules (A3: +1.1 % at ×4,
    /// +2.4 % at ×10; BENCHMARKS.md).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "F",
        default_value_t = STANDARD_MASS_SCALING,
        allow_negative_numbers = true
    )]
    pub mass_scaling: f64,

    /// The quasi-static certificate's rate check: run again at half the
    /// platen speed (a second run of twice the first one's cost) and
    /// require the force curve to move by less than 5 % over
    /// 2 % ≤ strain ≤ --strain (which must exceed 0.02).
    #[arg(long)]
    pub rate_check: bool,

    /// Threads for --types (one type per thread; 0 = all cores, at most
    /// 4096). Results do not depend on it; wall times may.
    #[arg(short = 'j', long, value_name = "N", default_value_t = 0, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(0, 4096))]
    pub threads: usize,

    /// No progress bars and no summary lines on stderr (errors are still
    /// reported).
    #[arg(short, long)]
    pub quiet: bool,

    /// Granule type and parameter overrides (`--friction` is also the
    /// granule–platen friction).
    #[command(flatten)]
    pub material: MaterialArgs,
}

/// One granule type to run, validated.
#[derive(Clone, Debug)]
struct Job {
    granule_type: GranuleType,
    params: PlatenParams,
    dir: PathBuf,
}

/// What one type's run left behind (its files are written).
struct Outcome {
    job: Job,
    result: RunResult,
    summary: Summary,
}

impl GranuleArgs {
    /// The experiment's parameters for `material`: the kernel's standard
    /// experiment with every option applied.
    pub fn params(&self, material: Material) -> PlatenParams {
        let mut p = PlatenParams::standard(material);
        p.elements.kind = self.element.into();
        p.elements.update.volume_fix = !self.literal_return;
        p.elements.hourglass_kappa = self.hourglass_kappa;
        p.damping_ratio = self.damping_ratio;
        p.approach_speed_m_s = self.speed_mm_s * 1.0e-3;
        p.final_strain = self.strain;
        p.time_step_safety = self.time_step_safety;
        if self.time_step_method == TimeStepArg::Element {
            p.time_step_method = TimeStepMethod::Element;
        }
        p.output_strain_interval = self.output_strain;
        p.gravity_m_s2 = if self.gravity { GRAVITY_M_S2 } else { 0.0 };
        p.symmetry = self.symmetry.into();
        p.mass_scaling = self.mass_scaling;
        p
    }

    /// Turns a kernel parameter rejection into a usage error naming the
    /// command-line flag (and the kernel field and range in its cause);
    /// other setup errors stay runtime errors.
    pub fn scene_error(&self, err: SceneError) -> anyhow::Error {
        let SceneError::InvalidParameter { field, value, .. } = err else {
            return anyhow::Error::new(err).context("cannot set up the platen experiment");
        };
        let message = match field {
            "damping_ratio" => format!("`--damping-ratio {value}` rejected"),
            "approach_speed_m_s" => format!(
                "`--speed-mm-s {}` rejected (allowed: 0.1 <= speed <= 10000 mm/s)",
                self.speed_mm_s
            ),
            "friction" => format!("`--friction {value}` rejected (granule-platen friction)"),
            "final_strain" => format!("`--strain {value}` rejected"),
            "time_step_safety" => format!("`--time-step-safety {value}` rejected"),
            "output_strain_interval" => format!(
                "`--output-strain {value}` rejected (allowed: 1e-6 <= interval <= `--strain` = {})",
                self.strain
            ),
            "hourglass_kappa" => format!("`--hourglass-kappa {value}` rejected"),
            "mass_scaling" => format!("`--mass-scaling {value}` rejected"),
            "gravity_m_s2" => {
                "`--gravity` rejected: it needs `--symmetry full` (in octant mode z = 0 is a \
                 symmetry plane)"
                    .to_owned()
            }
            other => format!("experiment parameter `{other}` = {value} rejected"),
        };
        anyhow::Error::new(err).context(InputError(message))
    }

    /// The floors the kernel leaves to its caller (its platen scene takes
    /// any speed and interval above zero, as a granule resting under
    /// gravity needs): a run of this command cannot be interrupted without
    /// losing it, so a speed or an output interval that would make it
    /// endless is a usage error.
    fn check_run_length(&self) -> anyhow::Result<()> {
        if !(MIN_SPEED_MM_S..).contains(&self.speed_mm_s) {
            return Err(InputError(format!(
                "`--speed-mm-s {}` rejected (allowed: {MIN_SPEED_MM_S} <= speed <= 10000 mm/s: the \
                 run's steps grow as 1/speed)",
                crate::numbers::short(self.speed_mm_s)
            ))
            .into());
        }
        if !(MIN_OUTPUT_STRAIN..).contains(&self.output_strain) {
            return Err(InputError(format!(
                "`--output-strain {}` rejected (allowed: 1e-6 <= interval <= `--strain`: each \
                 interval keeps a sample)",
                crate::numbers::short(self.output_strain)
            ))
            .into());
        }
        Ok(())
    }

    /// The granule types to run.
    fn types(&self) -> Vec<GranuleType> {
        match &self.types {
            Some(list) => list.0.clone(),
            None => vec![self.material.granule_type],
        }
    }

    /// Validates every type's material and experiment (usage errors name
    /// the flag) before anything is written.
    fn jobs(&self, mesh: &OwnedReference) -> anyhow::Result<Vec<Job>> {
        if self.rate_check && self.strain <= crate::quasi_static::RATE_CHECK_FROM_STRAIN {
            return Err(InputError(format!(
                "`--rate-check` needs `--strain` above {} (its window starts there; got {})",
                crate::quasi_static::RATE_CHECK_FROM_STRAIN,
                self.strain
            ))
            .into());
        }
        self.check_run_length()?;
        let mut jobs = Vec::new();
        for granule_type in self.types() {
            let material = MaterialArgs {
                granule_type,
                ..self.material
            }
            .material()?;
            let params = self.params(material);
            let time_step_s = run::check(params, mesh).map_err(|e| self.scene_error(e))?;
            let length = crate::run_length::RunLength {
                duration_s: params.final_strain * 1e-3 * self.diameter_mm
                    / params.approach_speed_m_s,
                time_step_s,
                wave_speed_m_s: granbed_kernel::granule::timestep::wave_speed(&material),
            };
            if let Some(message) = length.refusal(
                MAX_STEPS,
                "the material (`--youngs-modulus-pa`, `--poisson-ratio`, \
                 `--true-density-kg-m3`, `--eta0`), `--mass-scaling`, `--time-step-safety`, \
                 `--mesh`, `--speed-mm-s` and `--strain`",
            ) {
                return Err(
                    InputError(format!("granule {}: {message}", granule_type.name())).into(),
                );
            }
            let dir = if self.types.is_some() {
                self.out.join(granule_type.name())
            } else {
                self.out.clone()
            };
            jobs.push(Job {
                granule_type,
                params,
                dir,
            });
        }
        Ok(jobs)
    }

    /// Runs `job` on `mesh` and writes its CSV, summary and plot.
    fn run_job(
        &self,
        job: Job,
        mesh: &OwnedReference,
        bars: &MultiProgress,
    ) -> anyhow::Result<Outcome> {
        let name = job.granule_type.name();
        let bar = progress::Progress::new(bars, name, job.params.final_strain);
        let result = run::run_platens(job.params, mesh, &mut |s, t| bar.update(s, t));
        bar.finish();
        let result =
            result.map_err(|e| anyhow::Error::new(e).context(format!("granule {name}")))?;
        let setup = RunSetup {
            granule_type: name,
            mesh: self.mesh,
            nodes: mesh.positions.len(),
            hexes: mesh.hexes.len(),
            params: &job.params,
        };
        let mut summary = Summary::new(&setup, &result, None);
        let force_svg = write_outputs(&job.dir, &result, &summary)
            .with_context(|| format!("granule {name}: writing the outputs"))?;
        let title = format!(
            "Granule {name} ({} {}) at {:.1} % strain",
            summary.mesh,
            summary.symmetry,
            100.0 * result.samples.last().map_or(0.0, |s| s.strain)
        );
        let pictures = section::granule_sections(mesh, &job.params, &result, &title)
            .with_context(|| format!("granule {name}: the section pictures"))?;
        for file in [section::SECTION_SVG, section::DENSITY_SVG] {
            let path = job.dir.join(file);
            match pictures.iter().find(|(name, _)| *name == file) {
                Some((_, svg)) => outputs::write_text(&path, svg)?,
                // A failed run has none; an earlier run's must not stand in.
                None if path.is_file() => std::fs::remove_file(&path)
                    .with_context(|| format!("cannot remove `{}`", path.display()))?,
                None => {}
            }
        }
        let energy_svg = report::energy_svg(
            &format!(
                "Granule {name} ({} {}): where the platens' work went",
                summary.mesh, summary.symmetry
            ),
            &result.samples,
        )?;
        outputs::write_text(&job.dir.join(report::ENERGY_SVG), &energy_svg)?;
        let plots = [
            (outputs::FORCE_SVG, force_svg.as_str()),
            (report::ENERGY_SVG, energy_svg.as_str()),
        ];
        let write_report = |summary: &Summary| {
            report::write_report(&job.dir, summary, &plots)
                .with_context(|| format!("granule {name}: the report"))
        };
        write_report(&summary)?;
        // The rate check after the run's own outputs are written: a failed
        // check loses nothing (and leaves no earlier run's page).
        if self.rate_check && result.error.is_none() {
            let change = rate_change(job.params, mesh, &result).with_context(|| {
                format!("granule {name}: the rate check's run at half the platen speed")
            })?;
            summary = Summary::new(&setup, &result, Some(change));
            outputs::write_summary_json(&job.dir.join(outputs::SUMMARY_JSON), &summary)?;
            write_report(&summary)?;
        }
        Ok(Outcome {
            job,
            result,
            summary,
        })
    }

    /// Validates the options, runs every type (in parallel over types with
    /// `--types`), writes the outputs and the summary lines.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        let octant = self.symmetry == SymmetryArg::Octant;
        let radius = radius_of_diameter_mm(self.diameter_mm)?;
        let mesh = OwnedReference::sphere(radius, self.mesh, octant)?;
        let jobs = self.jobs(&mesh)?;
        if let Some(types) = &self.types {
            let given = [
                (self.material.yield_stress_pa, "--yield-stress-pa"),
                (self.material.eta0, "--eta0"),
            ];
            if let Some(w) = crate::material_args::check_type_overrides(&types.0, given)? {
                writeln!(streams.stderr, "warning: {w}")?;
            }
        }
        crate::bed::refuse_unfinished(&self.out, "granule")?;
        for dir in core::iter::once(&self.out).chain(jobs.iter().map(|j| &j.dir)) {
            crate::output::create_out_dir(dir)?;
        }
        let bars = progress::bars(self.quiet);
        let outcomes: Vec<anyhow::Result<Outcome>> = if jobs.len() == 1 {
            jobs.into_iter()
                .map(|j| self.run_job(j, &mesh, &bars))
                .collect()
        } else {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(self.threads)
                .build()
                .context("cannot start the worker threads")?;
            pool.install(|| {
                jobs.into_par_iter()
                    .map(|j| self.run_job(j, &mesh, &bars))
                    .collect()
            })
        };
        let outcomes: Vec<Outcome> = outcomes.into_iter().collect::<anyhow::Result<_>>()?;
        if self.types.is_some() {
            write_type_outputs(&self.out, &outcomes, self.mesh, self.symmetry.into())?;
        }
        for o in &outcomes {
            if !self.quiet {
                writeln!(streams.stderr, "{}", o.summary.line())?;
            }
            if o.result.error.is_none() && !o.summary.quasi_static.passed {
                writeln!(streams.stderr, "{}", o.summary.not_quasi_static())?;
            }
            // Why sigma_est is null or fitted over less than 0.1-0.4.
            for note in &o.summary.notes {
                writeln!(
                    streams.stderr,
                    "warning: granule {}: {note}",
                    o.summary.granule_type
                )?;
            }
        }
        kernel_failures(&outcomes)
    }
}

/// The rate check of a finished run `result` of `params`: the relative L2
/// change of its force curve when the platens move at half the speed
/// (same masses), over the certificate's strain window.
fn rate_change(
    params: PlatenParams,
    mesh: &OwnedReference,
    result: &RunResult,
) -> anyhow::Result<Real> {
    let slow = PlatenParams {
        approach_speed_m_s: 0.5 * params.approach_speed_m_s,
        ..params
    };
    let twin = run::run_platens(slow, mesh, &mut |_, _| {})?;
    if let Some(e) = twin.error {
        anyhow::bail!("the run failed: {e}");
    }
    let curve = |r: &RunResult| -> Vec<(Real, Real)> {
        r.samples
            .iter()
            .map(|s| (s.strain, s.mean_force()))
            .collect()
    };
    crate::quasi_static::rate_change(&curve(result), &curve(&twin), params.final_strain)
        .context("the curves do not cover the rate check's strain window")
}

/// A stress for a legend: in kPa with four significant digits from 1 kPa
/// to 1 GPa (granule yield stresses), otherwise in Pa with an exponent.
fn stress_text(pa: Real) -> String {
    let kpa = pa * 1e-3;
    if (1.0..1e6).contains(&kpa) {
        // 1 ≤ kPa < 10⁶: the exponent is 0..=5, the decimals 3 down to 0.
        let decimals = (3 - kpa.log10().floor() as i32).max(0) as usize;
        format!("{kpa:.decimals$} kPa")
    } else {
        format!("{pa:.4e} Pa")
    }
}

/// Writes the CSV, summary and plot of one run into `dir`; returns the
/// plot's SVG text (for the report).
fn write_outputs(dir: &Path, result: &RunResult, summary: &Summary) -> anyhow::Result<String> {
    outputs::write_force_csv(&dir.join(outputs::FORCE_CSV), &result.samples)?;
    outputs::write_summary_json(&dir.join(outputs::SUMMARY_JSON), summary)?;
    let fit = match (
        summary.slope_n_per_m,
        summary.intercept_n,
        summary.sigma_est_pa,
    ) {
        (Some(slope), Some(intercept), Some(sigma)) => {
            let [lo, hi] = summary
                .sigma_est_strain_range
                .unwrap_or(summary::FIT_STRAIN_RANGE);
            Some(plot::FitLine {
                slope_n_per_m: slope,
                intercept_n: intercept,
                x_range_m: [lo, hi].map(|e| e * result.diameter_m),
                label: format!("fit: σ_est = {}", stress_text(sigma)),
            })
        }
        _ => None,
    };
    let title = format!(
        "Granule {} ({} {}): platen force",
        summary.granule_type, summary.mesh, summary.symmetry
    );
    let label = format!("{} mean force", summary.granule_type);
    let curve = plot::Curve {
        label: &label,
        samples: &result.samples,
    };
    let svg = plot::force_displacement_svg(&title, &[curve], fit.as_ref())?;
    outputs::write_text(&dir.join(outputs::FORCE_SVG), &svg)?;
    Ok(svg)
}

/// Writes `types.csv` and the overlaid plot of a `--types` run into `dir`.
fn write_type_outputs(
    dir: &Path,
    outcomes: &[Outcome],
    mesh: MeshLevel,
    symmetry: Symmetry,
) -> anyhow::Result<()> {
    let rows: Vec<(GranuleType, &Summary)> = outcomes
        .iter()
        .map(|o| (o.job.granule_type, &o.summary))
        .collect();
    outputs::write_types_csv(&dir.join(outputs::TYPES_CSV), &rows)?;
    let curves: Vec<plot::Curve<'_>> = outcomes
        .iter()
        .map(|o| plot::Curve {
            label: o.job.granule_type.name(),
            samples: &o.result.samples,
        })
        .collect();
    let title = format!(
        "Granule types ({mesh} {}): platen force",
        symmetry_name(symmetry)
    );
    let svg = plot::force_displacement_svg(&title, &curves, None)?;
    outputs::write_text(&dir.join(outputs::TYPES_SVG), &svg)?;
    // Each run's directory, relative to the series' page.
    let dirs: Vec<String> = outcomes
        .iter()
        .map(|o| {
            o.job.dir.file_name().map_or_else(
                || o.job.granule_type.name().to_owned(),
                |n| n.to_string_lossy().into_owned(),
            )
        })
        .collect();
    let runs: Vec<(&str, &Summary)> = dirs
        .iter()
        .zip(outcomes)
        .map(|(dir, o)| (dir.as_str(), &o.summary))
        .collect();
    outputs::write_text(
        &dir.join(report::REPORT_FILE),
        &report::types_report_html(&svg, &runs),
    )
}

/// The error of the runs the kernel stopped (naming type, step, strain,
/// element and where the partial results are), or `Ok` if none.
fn kernel_failures(outcomes: &[Outcome]) -> anyhow::Result<()> {
    let failed = outcomes.iter().filter_map(|o| {
        let err = o.result.error?;
        let context = format!(
            "granule {}: the kernel stopped the run; the {} samples before it are in `{}` and \
             the summary (with its \"error\") in `{}`",
            o.job.granule_type,
            o.result.samples.len(),
            o.job.dir.join(outputs::FORCE_CSV).display(),
            o.job.dir.join(outputs::SUMMARY_JSON).display()
        );
        Some(anyhow::Error::new(err).context(context))
    });
    crate::output::all_failures(failed, "failed")
}

#[cfg(test)]
mod tests {
    use super::*;
    use granbed_kernel::element::force::DEFAULT_HOURGLASS_KAPPA;

    #[test]
    fn legend_stresses_are_in_kpa_with_four_digits() {
        assert_eq!(stress_text(44_609.6), "44.61 kPa");
        assert_eq!(stress_text(1_000.0), "1.000 kPa");
        assert_eq!(stress_text(162_131.0), "162.1 kPa");
        assert_eq!(stress_text(12.5), "1.2500e1 Pa");
        assert_eq!(stress_text(999_999_000.0), "999999 kPa");
    }

    #[test]
    fn defaults_are_the_kernels_standard_experiment() {
        use clap::Parser;
        #[derive(Parser)]
        struct Wrapper {
            #[command(flatten)]
            granule: GranuleArgs,
        }
        let args = Wrapper::try_parse_from(["test", "--out", "x"])
            .unwrap()
            .granule;
        let material = GranuleType::B2.params().validate().unwrap();
        assert_eq!(args.params(material), PlatenParams::standard(material));
        assert_eq!(args.hourglass_kappa, DEFAULT_HOURGLASS_KAPPA);
        assert_eq!(args.mesh, MeshLevel::STANDARD);
    }

    #[test]
    fn type_lists() {
        assert_eq!("all".parse::<TypeList>().unwrap().0, GranuleType::ALL);
        let list: TypeList = "a1, B2,c3".parse().unwrap();
        assert_eq!(list.to_string(), "A1,B2,C3");
        assert!("A1,A1".parse::<TypeList>().unwrap_err().contains("twice"));
        assert!("A1,D4".parse::<TypeList>().unwrap_err().contains("`D4`"));
    }
}
