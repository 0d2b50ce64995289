//! SIGINT and SIGTERM (and SIGHUP) during `granbed-cli bed`: the handler
//! only sets [`INTERRUPT`]; the run checks it after every step (the pour
//! at each of its rest checks, and stops there with nothing to keep), and
//! once it is set finishes that step, writes a checkpoint (atomically, as every
//! checkpoint) and the outputs so far (`compression.csv`, `summary.json`
//! with `"interrupted": true`), says how to resume, and the process exits
//! with status 130. A second signal ends the process at once.
//!
//! The binary installs the handler for `bed` only ([`install`], called by
//! `main`); the library never does on its own, so the test suites, which
//! drive the library in-process, keep the default signal handling and set
//! the flag themselves (or pass a flag of their own in
//! [`crate::bed::run::RunControl::interrupt`]).

use core::sync::atomic::{AtomicBool, Ordering};

/// Set by the signal handler: the run stops after the step it is in.
pub static INTERRUPT: AtomicBool = AtomicBool::new(false);

/// Exit status of a run stopped by a signal (128 + SIGINT's 2, as a shell
/// reports a process killed by Ctrl-C).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Installs the handler of SIGINT, SIGTERM and SIGHUP for this process:
/// the first signal sets [`INTERRUPT`] and says on stderr what happens
/// now, a second one exits at once with [`EXIT_INTERRUPTED`]. An error
/// (another handler installed already) is returned, not fatal to a run.
pub fn install() -> Result<(), ctrlc::Error> {
    ctrlc::set_handler(|| {
        if INTERRUPT.swap(true, Ordering::SeqCst) {
            eprintln!("\ngranbed-cli: second interrupt, quitting at once");
            std::process::exit(i32::from(EXIT_INTERRUPTED));
        }
        eprintln!(
            "\ngranbed-cli: interrupted; finishing the current step, then writing a checkpoint \
             and the outputs so far (a pour stops at its next rest check, with nothing to keep; \
             interrupt again to quit at once, losing them)"
        );
    })
}

/// An error marking a run stopped by a signal (exit status
/// [`EXIT_INTERRUPTED`]); its message says what was kept and how to
/// resume.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interrupted(pub String);

impl core::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.0)
    }
}

impl core::error::Error for Interrupted {}
