//! What the workspace's examples share, written here as a user would: a line to stdout that
//! stops quietly once its reader has gone, and a main that turns an error into status 1.

use std::io::Write;
use std::process::ExitCode;

/// The reader of stdout has gone.
#[derive(Debug)]
pub struct StdoutClosed;

impl std::fmt::Display for StdoutClosed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("stdout closed")
    }
}

impl std::error::Error for StdoutClosed {}

/// Writes one line to stdout.
///
/// # Errors
/// [`StdoutClosed`] when its reader has gone; any other write error.
pub fn write_line(line: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{line}") {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        other => Ok(other?),
    }
}

/// `println!` that returns an error instead of panicking when stdout is gone.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::support::write_line(::std::format_args!($($arg)*))
    };
}
pub(crate) use out;

/// Runs `job`: status 0 when it succeeded or stdout was closed, 1 with the error otherwise.
pub fn run(job: impl FnOnce() -> anyhow::Result<()>) -> ExitCode {
    match job() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<StdoutClosed>() => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
