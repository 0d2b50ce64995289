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
