//! Usage errors and the mapping from an error to the process exit status.
//!
//! | status | meaning |
//! |---|---|
//! | 0 | success, `--help`, `--version`; also a closed stdout (broken pipe, e.g. `| head`), silently |
//! | 1 | runtime failure: kernel error during a run, I/O error |
//! | 2 | usage or validation error: unknown flag, unparsable value, value out of range |
//! | 130 | a `bed` run stopped by SIGINT/SIGTERM after writing its checkpoint and outputs ([`crate::signal`]) |
//!
//! An error chain is a usage error if it holds a [`clap::Error`] or an
//! [`InputError`]; everything else is a runtime failure.

use core::fmt;
use std::io::{self, Write};

/// Exit status of a successful run.
pub const EXIT_SUCCESS: u8 = 0;
/// Exit status of a runtime failure (kernel error, I/O error).
pub const EXIT_FAILURE: u8 = 1;
/// Exit status of a usage or validation error.
pub const EXIT_USAGE: u8 = 2;

/// A rejected command-line input. Its message names the flag and the allowed
/// values; it marks the whole error chain as a usage error (status 2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputError(pub String);

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl core::error::Error for InputError {}

/// A rejected field of an input file (a scene's `die_diameter_mm`, …):
/// its message names the field and the allowed range, and it is a usage
/// error like [`InputError`]. The field is kept apart so that a command
/// whose flag set the field can name the flag instead.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldError {
    /// The field's name in the file.
    pub field: &'static str,
    /// The rejected value as text.
    pub value: String,
    /// The allowed range, in the field's units.
    pub allowed: String,
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "scene field `{}` = {} is out of range (allowed: {})",
            self.field, self.value, self.allowed
        )
    }
}

impl core::error::Error for FieldError {}

/// A usage error with `message` (which should name the flag).
pub fn input_error(message: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(InputError(message.into()))
}

/// True if `err` is a usage or validation error.
pub fn is_usage_error(err: &anyhow::Error) -> bool {
    err.downcast_ref::<clap::Error>().is_some()
        || err.downcast_ref::<InputError>().is_some()
        || err
            .chain()
            .any(|e| e.is::<InputError>() || e.is::<FieldError>())
}

/// True if `err` comes from writing to a closed pipe.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// The exit status for `err` (see the module docs).
pub fn exit_code(err: &anyhow::Error) -> u8 {
    if let Some(clap_err) = err.downcast_ref::<clap::Error>() {
        // 2 for usage errors; clap's statuses are small and non-negative.
        return u8::try_from(clap_err.exit_code()).unwrap_or(EXIT_USAGE);
    }
    if err.chain().any(|e| e.is::<crate::signal::Interrupted>()) {
        crate::signal::EXIT_INTERRUPTED
    } else if is_usage_error(err) {
        EXIT_USAGE
    } else if is_broken_pipe(err) {
        EXIT_SUCCESS
    } else {
        EXIT_FAILURE
    }
}

/// Prints `err` to `stderr` and returns its exit status.
///
/// The message is `error: ` followed by the whole chain, outermost first,
/// separated by `: `. clap's own errors are printed as clap renders them
/// (they already start with `error:` and end with a usage hint). A broken
/// pipe prints nothing.
pub fn report(err: &anyhow::Error, stderr: &mut dyn Write) -> u8 {
    let code = exit_code(err);
    // Failing to print the error leaves nothing better to do: ignore it.
    let _ = if let Some(clap_err) = err.downcast_ref::<clap::Error>() {
        write!(stderr, "{}", clap_err.render())
    } else if code == EXIT_SUCCESS {
        Ok(())
    } else {
        writeln!(stderr, "error: {err:#}")
    };
    let _ = stderr.flush();
    code
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context as _;

    #[test]
    fn statuses_follow_the_chain() {
        let usage = input_error("bad --x");
        assert_eq!(exit_code(&usage), EXIT_USAGE);
        let wrapped = Err::<(), _>(usage).context("outer").unwrap_err();
        assert_eq!(exit_code(&wrapped), EXIT_USAGE);
        let runtime = anyhow::anyhow!("kernel failed");
        assert_eq!(exit_code(&runtime), EXIT_FAILURE);
        let stopped = anyhow::Error::new(crate::signal::Interrupted("resume".into())).context("x");
        assert_eq!(exit_code(&stopped), 130);
        let pipe = anyhow::Error::new(io::Error::from(io::ErrorKind::BrokenPipe)).context("row 3");
        assert_eq!(exit_code(&pipe), EXIT_SUCCESS);
        let mut buf = Vec::new();
        assert_eq!(report(&wrapped, &mut buf), EXIT_USAGE);
        assert_eq!(String::from_utf8(buf).unwrap(), "error: outer: bad --x\n");
    }
}
