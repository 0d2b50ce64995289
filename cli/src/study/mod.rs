//! `granbed-cli study`: runs that measure the code rather than a material.
//!
//! * `work-precision` ([`work_precision`]): what each numerical setting
//!   costs and how far it moves the answer, against a reference run;
//! * `stability` ([`stability`]): every type in beds to 60 % and as single
//!   granules to 70 %, with the numerics of each run judged;
//! * `compare` ([`compare`]): the work-precision measures between two
//!   finished bed runs;
//! * `element-time` ([`element_time`]): the element loop's time per
//!   element-step on a bed checkpoint's state.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};

use crate::granule::TypeList;
use crate::material_args::MaterialArgs;
use crate::model::MeshLevel;
use crate::output::Streams;

pub mod bed_small;
pub mod compare;
pub mod element_time;
pub mod stability;
pub mod work_precision;

/// Options of `granbed-cli study`.
#[derive(Args, Debug)]
pub struct StudyArgs {
    /// The study.
    #[command(subcommand)]
    pub study: Study,
}

/// The studies.
#[derive(Subcommand, Debug)]
pub enum Study {
    /// Run time against error for the numerical settings of a scene (mesh,
    /// element and hourglass κ, time-step safety, mass scaling, loading
    /// speed), each changed alone from the default, against a reference
    /// run (finest mesh, F-bar, half speed, no mass scaling); writes
    /// `work_precision.csv` and the diagram `work_precision.svg`.
    WorkPrecision(WorkPrecisionArgs),
    /// The stability suite: every granule type in beds poured from
    /// several seeds, compressed to 60 % axial strain, and as single
    /// granules between platens to 70 %; per run the smallest Jacobian,
    /// the largest nodal speed, the deepest overlap (as the contact
    /// detection reports it, and in beds measured by geometry every 0.05
    /// of strain: the winding number of each neighbour's surface), the
    /// energy residual, the hourglass share and the wall time in
    /// `stability.csv`/`.json`, plots of the worst bed per type. Exits 1 if
    /// a run fails (an error, an inverted element, a residual ≥ 1 % of the
    /// punch work or either overlap ≥ 1 % of the element size).
    Stability(StabilityArgs),
    /// How far one finished bed run lies from another (the reference,
    /// first): the relative L2 distance of P(C), the relative errors of
    /// Kawakita's a and 1/b, and the ratios of steps, wall time and pair
    /// searches per step, from their `compression.csv` and
    /// `summary.json`.
    Compare(compare::CompareArgs),
    /// The element loop's time per element-step on one core, on
    /// the state of a bed checkpoint: every deformable granule's internal
    /// forces at the checkpoint's positions, from its C_p⁻¹, in timed passes
    /// (each from the checkpoint's state); prints the median and the
    /// fastest pass's ns per element-step and the share of elements that
    /// yielded.
    ElementTime(element_time::ElementTimeArgs),
}

/// The scene of a work-precision study.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum StudyScene {
    /// One granule between platens (octant), to 40 % strain.
    Granule,
    /// A small bed of the published scene (125 coarse 4x1 granules in a
    /// 5.65 mm die, to 30 %), the default also on further pours for the
    /// run-to-run spread.
    BedSmall,
}

/// Options of `granbed-cli study work-precision`.
#[derive(Args, Debug)]
pub struct WorkPrecisionArgs {
    /// The scene.
    #[arg(long, value_enum, default_value = "granule")]
    pub scene: StudyScene,

    /// Output directory, created if missing.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// A small grid (granule: on the coarse 4x1 mesh; bed: 15 granules in
    /// 4.2 mm to 30 %, two pours): seconds instead of tens of minutes;
    /// checks the machinery, not the defaults.
    #[arg(long)]
    pub quick: bool,

    /// bed-small: granules per bed (1..=100000; default 125; 15 with
    /// --quick).
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(1, crate::bed::scene::MAX_GRANULES as u64))]
    pub granules: Option<usize>,

    /// bed-small: die diameter, mm (more than 4 and at most 1000 granule
    /// diameters; default 5.65; 4.2 with --quick).
    #[arg(value_parser = crate::numbers::real, long, value_name = "MM", allow_negative_numbers = true)]
    pub die_diameter_mm: Option<f64>,

    /// bed-small: final axial strain (0 < C ≤ 0.9; default 0.3, with
    /// --quick too).
    #[arg(value_parser = crate::numbers::real, long, value_name = "C", allow_negative_numbers = true)]
    pub strain: Option<f64>,

    /// bed-small: mesh level of the granules (default 4x1).
    #[arg(long, value_name = "NxM")]
    pub mesh: Option<MeshLevel>,

    /// bed-small: poured beds for the spread, 2..=10 (default 3; 2 with
    /// --quick).
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u64>(2, 10))]
    pub pours: Option<u64>,

    /// bed-small: worker threads (0 = all cores; at most 4096).
    #[arg(short = 'j', long, value_name = "N", default_value_t = 0, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(0, 4096))]
    pub threads: usize,

    /// granule: several granule types instead of --type (`all` or a comma
    /// list such as `A3,B2,C3`): every setting runs on each, and the table
    /// holds each setting's largest error over the types and its summed
    /// wall time (with two or more types, each type's own table goes to
    /// `DIR/<TYPE>/`).
    #[arg(long, value_name = "LIST", conflicts_with = "granule_type")]
    pub types: Option<crate::granule::TypeList>,

    /// Granule type.
    #[command(flatten)]
    pub material: MaterialArgs,

    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Options of `granbed-cli study stability`. The defaults are the
/// CI-sized suite (coarse 4x1 granules); `--mesh 8x2` is the documented
/// long run on the standard mesh.
#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// Output directory, created if missing.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Granule types: `all` (A1…C3) or a comma list.
    #[arg(long, value_name = "LIST", default_value = "all")]
    pub types: TypeList,

    /// Beds per type, poured with seeds 1…N (1 ≤ N ≤ 10).
    #[arg(long, value_name = "N", default_value_t = 3, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u64>(1, 10))]
    pub beds: u64,

    /// Granules per bed (1 ≤ N ≤ 100000).
    #[arg(long, value_name = "N", default_value_t = 30, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(1, crate::bed::scene::MAX_GRANULES as u64))]
    pub granules: usize,

    /// Mesh level of the bed granules.
    #[arg(long, value_name = "NxM", default_value = "4x1")]
    pub mesh: MeshLevel,

    /// Die diameter, mm (more than 4 and at most 1000 granule diameters).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "MM",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    pub die_diameter_mm: f64,

    /// Final axial strain of the beds (0 < C ≤ 0.9).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "C",
        default_value_t = 0.6,
        allow_negative_numbers = true
    )]
    pub strain: f64,

    /// Mesh level of the single granules (octant).
    #[arg(long, value_name = "NxM", default_value = "8x2")]
    pub granule_mesh: MeshLevel,

    /// Final platen strain x/d of the single granules (0 < C ≤ 0.9).
    #[arg(value_parser = crate::numbers::real,
        long,
        value_name = "C",
        default_value_t = 0.7,
        allow_negative_numbers = true
    )]
    pub granule_strain: f64,

    /// Override the beds' maximum contact sweeps per step (1..=50; default:
    /// the published scene's), to show what the sweeps buy.
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<u32>(1, 50))]
    pub contact_sweeps: Option<u32>,

    /// Override the beds' speed watchdog (× punch speed; default: the
    /// published scene's; 1 ≤ r ≤ 1e9).
    #[arg(value_parser = crate::numbers::real, long, value_name = "R", allow_negative_numbers = true)]
    pub watchdog_speed_ratio: Option<f64>,

    /// Override the beds' contact-sweep tolerance (fraction of the element
    /// size, 0 < t ≤ 0.1; default: the published scene's).
    #[arg(value_parser = crate::numbers::real, long, value_name = "T", allow_negative_numbers = true)]
    pub sweep_tolerance: Option<f64>,

    /// Override the beds' mass scaling, 1 ≤ F ≤ 1e6 (default: the
    /// published scene's, selective with its ratio limit).
    #[arg(value_parser = crate::numbers::real, long, value_name = "F", allow_negative_numbers = true)]
    pub mass_scaling: Option<f64>,

    /// Override the beds' time-step floor of variable mass scaling,
    /// 0 ≤ r ≤ 1 (0: off; default: the published scene's).
    #[arg(value_parser = crate::numbers::real, long, value_name = "R", allow_negative_numbers = true)]
    pub time_step_floor: Option<f64>,

    /// Override the beds' rule for a node behind several faces (default:
    /// the published scene's, true: held against the nearest whatever its
    /// normal; false: physics.md's normal test, under which nodes at the
    /// folds of flattened granules sank unseen by the detection; the
    /// overlap by geometry shows them).
    #[arg(long, value_name = "BOOL")]
    pub nearest_penetrated_face: Option<bool>,

    /// Worker threads of the bed runs (0 = all cores; at most 4096).
    #[arg(short = 'j', long, value_name = "N", default_value_t = 0, allow_negative_numbers = true,
          value_parser = crate::numbers::whole::<usize>(0, 4096))]
    pub threads: usize,

    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl StudyArgs {
    /// Runs the study.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        match &self.study {
            Study::WorkPrecision(args) => args.run(streams),
            Study::Stability(args) => args.run(streams),
            Study::Compare(args) => args.run(streams),
            Study::ElementTime(args) => args.run(streams),
        }
    }
}
