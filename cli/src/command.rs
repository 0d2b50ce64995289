//! The top-level command line: [`Cli`] and its subcommands [`Command`].
//!
//! A new subcommand (`granule`, `pack`, `bed`) is a variant of [`Command`]
//! holding its clap `Args` struct from its own module, plus one arm in
//! [`Command::run`].

use clap::{Parser, Subcommand};

use crate::bed::BedArgs;
use crate::export_mesh::ExportMeshArgs;
use crate::granule::GranuleArgs;
use crate::output::Streams;
use crate::pack::PackArgs;
use crate::point::PointArgs;
use crate::study::StudyArgs;

/// granbed: a combined finite/discrete element simulator of granule-bed die
/// compaction.
///
/// Units are SI throughout; strains are positive in compression.
#[derive(Parser, Debug)]
#[command(name = "granbed-cli", version)]
pub struct Cli {
    /// What to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Drive one material point along a deformation path and write its
    /// stress history as CSV (calibration of material parameters).
    Point(PointArgs),
    /// Export the granule reference mesh (sphere or octant) as a
    /// CalculiX/Abaqus `.inp` file.
    ExportMesh(ExportMeshArgs),
    /// Compress one granule between two rigid platens; write the
    /// force–displacement table, a summary with the granule yield stress
    /// estimate σ_est, and a plot to a directory.
    Granule(GranuleArgs),
    /// Pour rigid spheres into the die and let them settle under gravity;
    /// write the packing (the start of a bed compression), a summary with
    /// the bed height, packing fractions and coordination number, and a
    /// VTK view to a directory.
    Pack(PackArgs),
    /// Compress a bed: pour it (as `pack`), make every sphere a
    /// finite-element granule and press the upper punch to the final
    /// strain; write the compression profile and a summary with the
    /// Kawakita fit. Without arguments it runs the published scene.
    // Boxed: its options are most of the enum's size.
    Bed(Box<BedArgs>),
    /// Studies of the code itself: `work-precision` (what each numerical
    /// setting costs and how far it moves the answer), `stability` (every
    /// granule type far past 30 % strain), `compare` (how far one bed run
    /// lies from another) and `element-time` (the element's time per
    /// element-step on a checkpoint's state).
    Study(StudyArgs),
}

impl Command {
    /// Runs the subcommand on `streams`.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        match self {
            Self::Point(args) => args.run(streams),
            Self::ExportMesh(args) => args.run(streams),
            Self::Granule(args) => args.run(streams),
            Self::Pack(args) => args.run(streams),
            Self::Bed(args) => args.run(streams),
            Self::Study(args) => args.run(streams),
        }
    }
}
