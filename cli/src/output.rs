//! The standard streams a command writes to, and `--out` destinations.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::Context as _;

/// The standard streams of a run: results (when not sent to a file) go to
/// `stdout`; summaries and diagnostics to `stderr`.
pub struct Streams<'a> {
    /// Standard output.
    pub stdout: &'a mut dyn Write,
    /// Standard error.
    pub stderr: &'a mut dyn Write,
}

/// A buffered result destination: a file, or standard output.
///
/// Dropping it does not report write errors: call [`Output::finish`] (or
/// `flush`) before reporting success.
pub struct Output<'a> {
    /// Human-readable name for messages: the path, or `stdout`.
    name: String,
    writer: BufWriter<Box<dyn Write + 'a>>,
}

impl<'a> Output<'a> {
    /// Opens the `--out` destination: `None` or `-` is `stdout`, anything
    /// else a file created (or truncated) at that path.
    pub fn open(path: Option<&Path>, stdout: &'a mut dyn Write) -> anyhow::Result<Self> {
        match path {
            None => Ok(Self::stdout(stdout)),
            Some(p) if p == Path::new("-") => Ok(Self::stdout(stdout)),
            Some(p) => {
                let file = File::create(p)
                    .with_context(|| format!("cannot create output file `{}`", p.display()))?;
                Ok(Self {
                    name: format!("`{}`", p.display()),
                    writer: BufWriter::new(Box::new(file)),
                })
            }
        }
    }

    fn stdout(stdout: &'a mut dyn Write) -> Self {
        Self {
            name: "stdout".to_owned(),
            writer: BufWriter::new(Box::new(stdout)),
        }
    }

    /// The destination's name for messages: a quoted path or `stdout`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Flushes everything written so far to the destination.
    pub fn finish(&mut self) -> anyhow::Result<()> {
        self.writer
            .flush()
            .with_context(|| format!("cannot write to {}", self.name))
    }
}

impl Write for Output<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer.flush()
    }
}

/// Creates the output directory `dir` (and its parents) if missing. A
/// path that names an existing file is a usage error (exit status 2)
/// saying so, before any work is done; other failures (permissions, a full
/// disk) are runtime errors naming the directory.
pub fn create_out_dir(dir: &Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(crate::error::input_error(format!(
            "the output directory `{}` is a file: --out names a directory (created if missing)",
            dir.display()
        )));
    }
    // A file where a parent directory would have to be: the same mistake.
    if let Some(file) = dir.ancestors().skip(1).find(|a| a.is_file()) {
        return Err(crate::error::input_error(format!(
            "the output directory `{}` cannot be made: `{}` is a file",
            dir.display(),
            file.display()
        )));
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output directory `{}`", dir.display()))
}

/// Creates (or truncates) the output file `path` for buffered writing.
pub fn create_file(path: &Path) -> anyhow::Result<BufWriter<File>> {
    let file = File::create(path)
        .with_context(|| format!("cannot create output file `{}`", path.display()))?;
    Ok(BufWriter::new(file))
}

/// Flushes `w`, naming `path` on failure.
pub fn finish_file(mut w: impl Write, path: &Path) -> anyhow::Result<()> {
    w.flush()
        .with_context(|| format!("cannot write to `{}`", path.display()))
}

/// Writes `text` to `path` (created or truncated), naming `path` on failure.
pub fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    let mut w = create_file(path)?;
    w.write_all(text.as_bytes())
        .with_context(|| format!("cannot write to `{}`", path.display()))?;
    finish_file(w, path)
}

/// Writes `value` as pretty-printed JSON (and a final line break) to `path`.
/// Floats are round-trip exact; non-finite ones become `null`.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    let mut w = create_file(path)?;
    serde_json::to_writer_pretty(&mut w, value)
        .and_then(|()| writeln!(w).map_err(serde_json::Error::io))
        .with_context(|| format!("cannot write to `{}`", path.display()))?;
    finish_file(w, path)
}

/// The field `key` (with its colon) of a Linux `/proc` file of `kB`
/// lines, such as `/proc/meminfo` or `/proc/self/status`, in bytes; `None`
/// where the file or the field cannot be read.
pub fn proc_kib_field(path: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// `num / den`, or `None` (JSON `null`) if that is not a finite number.
pub fn finite_ratio(num: f64, den: f64) -> Option<f64> {
    let r = num / den;
    r.is_finite().then_some(r)
}

/// `text` with the five markup special characters escaped, for XML (VTK
/// files) and HTML alike (the apostrophe as `&#39;`, which both read).
pub fn escape_markup(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// `Ok` if `failures` is empty, else the first failure with the others
/// listed in its context ("N granule types `verb`; also: …"), so a batch
/// of runs reports every failure, not just one.
pub fn all_failures(
    mut failures: impl Iterator<Item = anyhow::Error>,
    verb: &str,
) -> anyhow::Result<()> {
    let Some(first) = failures.next() else {
        return Ok(());
    };
    let others: Vec<String> = failures.map(|e| format!("{e:#}")).collect();
    if others.is_empty() {
        Err(first)
    } else {
        Err(first.context(format!(
            "{} granule types {verb}; also: {}",
            others.len() + 1,
            others.join("; ")
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_proc_field_reads_in_bytes_and_a_missing_one_is_none() {
        let dir = std::env::temp_dir().join(format!("granbed-proc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("meminfo");
        std::fs::write(&path, "MemTotal:       24576 kB\nMemFree:  12 kB\n").unwrap();
        let path = path.to_str().unwrap();
        assert_eq!(proc_kib_field(path, "MemTotal:"), Some(24576 * 1024));
        assert_eq!(proc_kib_field(path, "MemFree:"), Some(12 * 1024));
        assert_eq!(proc_kib_field(path, "VmHWM:"), None);
        assert_eq!(proc_kib_field("/no/such/file", "MemTotal:"), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
