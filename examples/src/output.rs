//! Standard output that ends quietly when its reader goes away, and the examples' exit status.
//!
//! `println!` panics when stdout is a closed pipe (`cargo run --release --example scan_stats |
//! head -1`). The examples print with [`out!`](crate::out) instead: on a broken pipe it returns
//! [`StdoutClosed`] as an error, which the example's `?` carries up to [`run`], and [`run`] ends
//! the program with status 0 and no message.

use std::fmt;
use std::io::{self, Write};
use std::process::ExitCode;

/// `println!` for the examples: writes one line to stdout and evaluates to `anyhow::Result<()>`,
/// an error of [`StdoutClosed`](crate::StdoutClosed) when the reader has gone. Use it with `?`
/// inside a job given to [`run`](crate::run).
#[macro_export]
macro_rules! out {
    () => {
        $crate::write_line(::std::format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::write_line(::std::format_args!($($arg)*))
    };
}

/// The reader of stdout has gone (a broken pipe): the example stops, quietly and successfully.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StdoutClosed;

impl fmt::Display for StdoutClosed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("stdout was closed")
    }
}

impl std::error::Error for StdoutClosed {}

/// Writes `line` and a newline to stdout (what [`out!`](crate::out) calls).
///
/// # Errors
/// [`StdoutClosed`] on a broken pipe; any other write error with the context "writing to stdout".
pub fn write_line(line: fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut stdout = io::stdout().lock();
    match writeln!(stdout, "{line}") {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("writing to stdout")),
    }
}

/// Runs an example's job and turns its result into the exit status: 0 when it succeeded or when
/// stdout was closed ([`StdoutClosed`], nothing printed), otherwise 1 with `error: ` and the
/// error's chain on one line of stderr.
///
/// Command-line errors never reach here: `clap` prints them with the usage and exits with 2.
pub fn run(job: impl FnOnce() -> anyhow::Result<()>) -> ExitCode {
    match job() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<StdoutClosed>() => ExitCode::SUCCESS,
        Err(e) => {
            let reason = format!("{e:#}").replace('\n', " ");
            eprintln!("error: {reason}");
            ExitCode::FAILURE
        }
    }
}
