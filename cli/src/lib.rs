//! # granbed-cli
//!
//! The command-line driver of granbed. Everything lives in this library; the
//! binary (`src/main.rs`) only hands the process's arguments and standard
//! streams to [`run`] and maps a failure to an exit status with
//! [`error::report`], so the test suites drive exactly the code a user runs.
//!
//! Modules:
//! * [`command`]: the top-level parser [`Cli`] and its subcommands;
//! * [`point`]: `granbed-cli point`, the material-point explorer;
//! * [`export_mesh`]: `granbed-cli export-mesh`, the mesh as CalculiX `.inp`;
//! * [`granule`]: `granbed-cli granule`, the single-granule platen experiment;
//! * [`pack`]: `granbed-cli pack`, the pour of rigid spheres into the die;
//! * [`bed`]: `granbed-cli bed`, the compression of a poured bed (the main job);
//! * [`assembly`]: many finite-element granules in contact with each other and walls;
//! * [`model`]: owned buffers for the kernel's meshes;
//! * [`material_args`]: `--type` and the material-parameter overrides;
//! * [`output`]: the standard streams and `--out` destinations;
//! * [`numbers`]: the value parser of whole-number flags (range in its message);
//! * [`signal`]: SIGINT/SIGTERM during `bed`: a stop flag the run checks;
//! * [`quasi_static`]: the quasi-static certificate of the summaries;
//! * [`csv`]: a small CSV writer with round-trip exact floats;
//! * [`vtk`]: a VTK XML unstructured-grid (`.vtu`) writer;
//! * [`error`]: usage errors and the exit-status mapping.
//!
//! Exit status: 0 success (and `--help`, `--version`), 1 runtime failure
//! (kernel error, I/O error), 2 usage or validation error (unknown flag, bad
//! value, parameter out of range), 130 a `bed` run stopped by SIGINT or
//! SIGTERM (after writing a checkpoint and its outputs).

use std::ffi::OsString;
use std::io::Write;

use clap::Parser;

pub mod assembly;
pub mod bed;
pub mod command;
pub mod csv;
pub mod error;
pub mod export_mesh;
pub mod granule;
pub mod material_args;
pub mod model;
pub mod numbers;
pub mod output;
pub mod pack;
pub mod plot;
pub mod point;
pub mod progress;
pub mod quasi_static;
pub mod signal;
pub mod study;
pub mod vtk;

pub use command::{Cli, Command};
pub use output::Streams;

/// Parses `args` (the first item is the program name, as in
/// [`std::env::args_os`]) and runs the command.
///
/// Results go to `stdout` (or the command's `--out` file), the summary and
/// diagnostics to `stderr`. `--help` and `--version` print to `stdout` and
/// succeed. A failure is returned, not printed: pass it to
/// [`error::report`] for the message and the exit status.
pub fn run<I, T>(args: I, stdout: &mut dyn Write, stderr: &mut dyn Write) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        // --help and --version arrive as "errors" meant for stdout.
        Err(e) if !e.use_stderr() => {
            write!(stdout, "{}", e.render())?;
            stdout.flush()?;
            return Ok(());
        }
        Err(e) => return Err(e.into()),
    };
    cli.command.run(&mut Streams { stdout, stderr })
}
