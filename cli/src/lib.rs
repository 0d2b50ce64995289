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
pub mod html;
pub mod material_args;
pub mod model;
pub mod numbers;
pub mod output;
pub mod pack;
pub mod plot;
pub mod point;
pub mod progress;
pub mod quasi_static;
pub mod run_length;
pub mod signal;
pub mod study;
pub mod vtk;

pub use command::{Cli, Command};

/// `args` with every value that is a negative number clap would take for a
/// flag (`-1e-3`, `-.5`, `-inf`: clap's `allow_negative_numbers` knows only
/// digits, one dot and an unsigned exponent) joined to the long flag before
/// it: `--strain -1e-3` becomes `--strain=-1e-3`. Nothing else changes: a
/// word that parses as a number is never a flag of this program, and a
/// flag that takes no value then says so itself.
pub fn numeric_values_joined<I, T>(args: I) -> Vec<OsString>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString>,
{
    let mut out: Vec<OsString> = Vec::new();
    for arg in args.into_iter().map(Into::into) {
        let negative_number = arg
            .to_str()
            .is_some_and(|s| s.starts_with('-') && s.parse::<f64>().is_ok());
        let after_long_flag = out
            .last()
            .and_then(|f| f.to_str())
            .is_some_and(|f| f.len() > 2 && f.starts_with("--") && !f.contains('='));
        if negative_number && after_long_flag {
            let flag = out.pop().unwrap_or_default();
            let mut joined = flag;
            joined.push("=");
            joined.push(&arg);
            out.push(joined);
        } else {
            out.push(arg);
        }
    }
    out
}
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
    let cli = match Cli::try_parse_from(numeric_values_joined(args)) {
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

#[cfg(test)]
mod tests {
    use super::numeric_values_joined;

    /// Negative numbers clap would not take as values are joined to the
    /// long flag before them; everything else is left as it is.
    #[test]
    fn negative_numbers_are_joined_to_their_flag() {
        let joined = |args: &[&str]| -> Vec<String> {
            numeric_values_joined(args.iter().copied())
                .into_iter()
                .map(|a| a.into_string().unwrap())
                .collect()
        };
        assert_eq!(
            joined(&["granbed-cli", "point", "--strain", "-1e-3", "--steps", "10"]),
            ["granbed-cli", "point", "--strain=-1e-3", "--steps", "10"]
        );
        assert_eq!(
            joined(&["x", "--a", "-.5", "--b", "-inf"]),
            ["x", "--a=-.5", "--b=-inf"]
        );
        // Already joined, after a short flag, a word, or no flag at all.
        for args in [
            &["x", "--a=-1", "-2"][..],
            &["x", "-j", "-1"],
            &["x", "--a", "-b"],
            &["x", "-1e-3"],
            &["x", "--", "-1"],
        ] {
            assert_eq!(joined(args), args, "{args:?}");
        }
    }
}
