//! `granbed-cli`: the command-line driver of granbed.
//!
//! A thin shell over the `granbed_cli` library: see its docs for the
//! commands and the exit statuses (0 success, 1 runtime failure, 2 usage or
//! validation error).

use std::io;
use std::process::ExitCode;

fn main() -> ExitCode {
    // The workspace builds for x86-64-v3 (.cargo/config.toml): on a processor
    // without AVX2 the first vector instruction would kill the process with
    // SIGILL, so say why before any runs.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    if !granbed_kernel::element::batch::has_avx2() {
        eprintln!(
            "error: this build of granbed-cli needs AVX2 (x86-64-v3), which this processor \
             lacks; rebuild it with RUSTFLAGS=\"-C target-cpu=x86-64\" (README.md)"
        );
        return ExitCode::from(2);
    }
    // `bed` stops cleanly on SIGINT/SIGTERM (granbed_cli::signal): the run
    // finishes its step and writes a checkpoint and its outputs. The other
    // commands keep the default handling (they die at once). The subcommand
    // is always the first argument (the top level has no other options).
    if std::env::args_os().nth(1).is_some_and(|a| a == "bed")
        && let Err(e) = granbed_cli::signal::install()
    {
        eprintln!("warning: cannot handle SIGINT/SIGTERM ({e}); an interrupt kills the run");
    }
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => ExitCode::from(granbed_cli::error::report(&err, &mut io::stderr().lock())),
    }
}

/// Runs this process's command line on its standard streams.
///
/// stderr is passed unlocked: the progress bars (indicatif) write to it from
/// worker threads while a command runs, and would wait forever for a lock
/// held here by the main thread.
fn run() -> anyhow::Result<()> {
    granbed_cli::run(
        std::env::args_os(),
        &mut io::stdout().lock(),
        &mut io::stderr(),
    )
}
