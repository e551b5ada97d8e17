//! Helpers every verb shares: one-line errors, reports, stdout, the list of
//! written files, timing.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use anyhow::Context;

use subdyn::io::{MeshFormat, atomic_write};
use subdyn::math::{Point3, bbox_diagonal, bounding_box};

/// Prints `subdyn: error: <message>` as a single line on stderr.
pub fn print_error(err: &anyhow::Error) {
    eprintln!("subdyn: error: {}", error_line(err));
}

/// The causes of an error chain joined with `: ` on one line, leaving out a
/// cause whose text the line already holds (`subdyn::Error::Io` shows its
/// source itself).
pub fn error_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = one_line(&cause.to_string());
        if text.is_empty() || line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

/// Collapses whitespace runs containing newlines into single spaces.
pub fn one_line(text: &str) -> String {
    text.split(['\n', '\r'])
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Replaces the default panic message (several lines and a backtrace hint)
/// by one line naming the place: a panic is a bug in subdyn, never the
/// user's fault, but the CLI still keeps its one-line promise.
pub fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!(
            "subdyn: internal error{place}: {}; this is a bug, please report it",
            one_line(&message)
        );
    }));
}

/// Turns a library error about `path` into an `anyhow` error that names the
/// file, unless the message already does (parse and I/O errors do).
pub fn about_file(err: subdyn::Error, path: &Path) -> anyhow::Error {
    let shown = path.display().to_string();
    if err.to_string().contains(&shown) {
        anyhow::Error::new(err)
    } else {
        anyhow::Error::new(err).context(shown)
    }
}

/// Fails early (before any work) when `path`'s extension names no mesh format
/// or its directory does not exist.
pub fn check_mesh_output(path: &Path) -> anyhow::Result<()> {
    MeshFormat::from_path(path)?;
    check_output_dir(path)
}

/// Fails early (before any work) when no file can be written at `path` (its
/// directory is missing or read-only, or `path` is a directory), rather than
/// after a long computation.
pub fn check_output_dir(path: &Path) -> anyhow::Result<()> {
    Ok(subdyn::io::check_writable(path)?)
}

/// Writes a JSON report atomically (pretty-printed, trailing newline).
pub fn write_report(path: &Path, report: &serde_json::Value) -> anyhow::Result<()> {
    atomic_write(path, |w| {
        serde_json::to_writer_pretty(&mut *w, report)?;
        w.write_all(b"\n")
    })
    .with_context(|| format!("cannot write the report {}", path.display()))
}

/// Writes `text` to stdout; a closed pipe (`subdyn info x | head`) is not an error.
pub fn print_stdout(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::new(e).context("cannot write to stdout"))
        }
        _ => Ok(()),
    }
}

/// The files a verb wrote, in the order it wrote them. Every verb ends its
/// output with [`Written::lines`]: one `wrote <path> (<what>)` line per file,
/// so a user (or a script) finds every output the same way whatever the verb.
#[derive(Debug, Default)]
pub struct Written(Vec<(PathBuf, String)>);

impl Written {
    /// No file yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records that `path` was written; `what` says what it holds, e.g.
    /// `"control mesh"` or `"report"`.
    pub fn add(&mut self, path: &Path, what: impl Into<String>) {
        self.0.push((path.to_path_buf(), what.into()));
    }

    /// One line per file: `wrote <path> (<what>)`.
    pub fn lines(&self) -> String {
        self.0
            .iter()
            .map(|(path, what)| format!("wrote {} ({what})\n", path.display()))
            .collect()
    }

    /// Prints `text` then [`Written::lines`] on stdout once the run's files
    /// are in place: the text waits for [`print_pending`], which the command
    /// line calls after renaming the staged outputs, so no `wrote` line names
    /// a file that a failed commit left out.
    pub fn print_after(&self, text: &str) -> anyhow::Result<()> {
        let mut pending = PENDING.lock().unwrap_or_else(PoisonError::into_inner);
        pending.push_str(text);
        pending.push_str(&self.lines());
        Ok(())
    }
}

/// What [`Written::print_after`] holds back until the outputs are committed.
static PENDING: Mutex<String> = Mutex::new(String::new());

/// Prints (and forgets) what [`Written::print_after`] held back.
pub fn print_pending() -> anyhow::Result<()> {
    let text = std::mem::take(&mut *PENDING.lock().unwrap_or_else(PoisonError::into_inner));
    print_stdout(&text)
}

/// Prints a warning line on stderr unless `quiet`.
pub fn warn(quiet: bool, message: &str) {
    if !quiet {
        eprintln!("subdyn: warning: {}", one_line(message));
    }
}

/// Seconds since `start`.
pub fn seconds(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// Runs `f` and returns its value with the seconds it took.
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let value = f();
    (value, seconds(start))
}

/// The bounding box of `points` as JSON `{min, max, diagonal}` (null when empty).
pub fn bbox_json(points: &[Point3]) -> serde_json::Value {
    match bounding_box(points) {
        Some((lo, hi)) => serde_json::json!({
            "min": [lo.x, lo.y, lo.z],
            "max": [hi.x, hi.y, hi.z],
            "diagonal": bbox_diagonal(points),
        }),
        None => serde_json::Value::Null,
    }
}

/// `1234567` as `1,234,567`.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_groups_digits() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(40_097), "40,097");
        assert_eq!(thousands(1_597_696), "1,597,696");
    }

    #[test]
    fn error_line_does_not_repeat_the_source() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let err = anyhow::Error::new(subdyn::Error::io("a.obj", io));
        assert_eq!(error_line(&err), "a.obj: no such file");
        let err = anyhow::anyhow!("inner\nline").context("outer");
        assert_eq!(error_line(&err), "outer: inner line");
    }

    #[test]
    fn written_names_every_file_one_per_line() {
        let mut w = Written::new();
        w.add(Path::new("out/fit.obj"), "control mesh");
        w.add(&PathBuf::from("r.json"), "report");
        assert_eq!(
            w.lines(),
            "wrote out/fit.obj (control mesh)\nwrote r.json (report)\n"
        );
        assert_eq!(Written::new().lines(), "");
    }

    #[test]
    fn one_line_joins_lines() {
        assert_eq!(one_line("a\n  b\r\n\nc"), "a b c");
    }
}
