//! `granbed-cli study`: runs that measure the code rather than a material.
//!
//! * `work-precision` ([`work_precision`]): what each numerical setting
//!   costs and how far it moves the answer, against a reference run.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};

use crate::material_args::MaterialArgs;
use crate::output::Streams;

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
}

/// The scene of a work-precision study.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum StudyScene {
    /// One granule between platens (octant), to 40 % strain.
    Granule,
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

    /// A small grid on the coarse 4x1 mesh (seconds instead of tens of
    /// minutes; checks the machinery, not the defaults).
    #[arg(long)]
    pub quick: bool,

    /// Granule type.
    #[command(flatten)]
    pub material: MaterialArgs,

    /// No progress lines on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl StudyArgs {
    /// Runs the study.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        match &self.study {
            Study::WorkPrecision(args) => args.run(streams),
        }
    }
}
