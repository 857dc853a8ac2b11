//! Progress of long runs (mapping, replaying a recording, navigating) on stderr: an `indicatif`
//! bar, with the time left when the length is known, when stderr is a terminal; otherwise (a log
//! file, a pipe, CI) a plain line every few seconds and one at the end.

use std::io::{IsTerminal, stderr};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Seconds between plain progress lines when stderr is not a terminal.
const LINE_INTERVAL: Duration = Duration::from_secs(5);

/// Progress of one long loop: `position` of `len` items (scans, samples, cycles) and a short
/// message of what has been done so far.
///
/// ```no_run
/// let mut progress = spot_nav_examples::Progress::new("mapping", "scans", Some(878));
/// for n in 1..=878 {
///     progress.update(n, format!("{} keyframes", n / 2));
/// }
/// progress.finish();
/// ```
#[derive(Debug)]
pub struct Progress {
    header: Header,
    sink: Sink,
}

/// What every plain line starts with, and the clock for its times.
#[derive(Debug)]
struct Header {
    label: String,
    unit: String,
    len: Option<u64>,
    started: Instant,
}

#[derive(Debug)]
enum Sink {
    Bar(ProgressBar),
    Lines {
        last_line: Instant,
        position: u64,
        message: String,
    },
}

impl Progress {
    /// Starts reporting a loop called `label` over `len` items (when known) counted in `unit`.
    #[must_use]
    pub fn new(label: &str, unit: &str, len: Option<u64>) -> Self {
        let started = Instant::now();
        let sink = if stderr().is_terminal() {
            // `{` and `}` in the label or unit would be template keys.
            let text = |s: &str| s.replace(['{', '}'], "");
            let (label_text, unit_text) = (text(label), text(unit));
            let (bar, template) = match len {
                Some(n) => (
                    ProgressBar::new(n),
                    format!(
                        "{label_text} [{{bar:30}}] {{pos}}/{{len}} {unit_text}{{msg}} ({{elapsed}}, {{eta}} left)"
                    ),
                ),
                None => (
                    ProgressBar::no_length(),
                    format!("{label_text} {{spinner}} {{pos}} {unit_text}{{msg}} ({{elapsed}})"),
                ),
            };
            let style = ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style.progress_chars("=> "));
            if len.is_none() {
                bar.enable_steady_tick(Duration::from_millis(200));
            }
            Sink::Bar(bar)
        } else {
            Sink::Lines {
                last_line: started,
                position: 0,
                message: String::new(),
            }
        };
        Self {
            header: Header {
                label: label.to_owned(),
                unit: unit.to_owned(),
                len,
                started,
            },
            sink,
        }
    }

    /// `position` items done; `message` (may be empty) says what they gave, e.g. `"120
    /// keyframes, 1 loop"`.
    pub fn update(&mut self, position: u64, message: impl Into<String>) {
        let message = message.into();
        match &mut self.sink {
            Sink::Bar(bar) => {
                bar.set_position(position);
                bar.set_message(separated(&message));
            }
            Sink::Lines {
                last_line,
                position: p,
                message: m,
            } => {
                *p = position;
                *m = message;
                if last_line.elapsed() >= LINE_INTERVAL {
                    *last_line = Instant::now();
                    eprintln!("{}", self.header.line(position, m, false));
                }
            }
        }
    }

    /// A line of its own about one item (e.g. a skipped scan), printed above the bar.
    pub fn note(&self, line: &str) {
        match &self.sink {
            Sink::Bar(bar) => bar.println(line),
            Sink::Lines { .. } => eprintln!("{line}"),
        }
    }

    /// The loop is over: the bar stays drawn at its last state, or a last plain line is printed.
    pub fn finish(self) {
        match &self.sink {
            Sink::Bar(bar) => bar.finish(),
            Sink::Lines {
                position, message, ..
            } => eprintln!("{}", self.header.line(*position, message, true)),
        }
    }
}

impl Header {
    /// A plain progress line: `mapping: 300/878 scans, 150 keyframes (6 s, about 12 s left)`.
    fn line(&self, position: u64, message: &str, done: bool) -> String {
        let elapsed = self.started.elapsed().as_secs_f64();
        let count = self
            .len
            .map_or_else(|| position.to_string(), |n| format!("{position}/{n}"));
        let time = match self.len {
            _ if done => format!("done in {elapsed:.1} s"),
            Some(n) if position > 0 => {
                let left = elapsed * (n.saturating_sub(position)) as f64 / position as f64;
                format!("{elapsed:.0} s, about {left:.0} s left")
            }
            _ => format!("{elapsed:.0} s"),
        };
        format!(
            "{}: {count} {}{} ({time})",
            self.label,
            self.unit,
            separated(message)
        )
    }
}

/// `", message"`, or nothing for an empty message.
fn separated(message: &str) -> String {
    if message.is_empty() {
        String::new()
    } else {
        format!(", {message}")
    }
}
