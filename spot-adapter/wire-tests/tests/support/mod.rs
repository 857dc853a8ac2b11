//! The fake Spot (Python, official `bosdyn-api` servicers) started by the tests, in a venv made
//! on first use under `target/tmp/py-fake-spot` with the pinned packages of
//! `fake_spot/requirements.txt`.
//!
//! A missing `python3` or an unreachable package index fails the test with the reason (a
//! skipped test would pass without checking anything).

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

use serde_json::Value;
use spot_adapter::grpc::{Credentials, SpotConfig};

pub const USERNAME: &str = "operator";
pub const PASSWORD: &str = "correct-horse-battery-staple";

/// `fake_spot/` of the wire tests, also when this module is included by another package's
/// tests (the examples').
fn fake_dir() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("fake_spot");
    if here.is_dir() {
        here
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../spot-adapter/wire-tests/fake_spot")
    }
}

/// The venv's python, made on first use.
pub fn python() -> PathBuf {
    static PYTHON: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    match PYTHON.get_or_init(make_venv) {
        Ok(p) => p.clone(),
        Err(reason) => panic!("the fake Spot cannot run: {reason}"),
    }
}

fn make_venv() -> Result<PathBuf, String> {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("py-fake-spot");
    let python = venv.join("bin").join("python");
    let requirements = std::fs::read_to_string(fake_dir().join("requirements.txt"))
        .map_err(|e| format!("fake_spot/requirements.txt: {e}"))?;
    let stamp = venv.join("installed-requirements.txt");
    if python.exists() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == requirements) {
        return Ok(python);
    }
    let run = |command: &mut Command, what: &str| -> Result<(), String> {
        let output = command
            .output()
            .map_err(|e| format!("{what}: cannot start: {e} (is python3 installed?)"))?;
        if output.status.success() {
            Ok(())
        } else {
            Err(format!(
                "{what} failed ({}): {}",
                output.status,
                String::from_utf8_lossy(&output.stderr)
            ))
        }
    };
    run(
        Command::new("python3")
            .args(["-m", "venv", "--clear"])
            .arg(&venv),
        "python3 -m venv",
    )?;
    run(
        Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "-r",
            ])
            .arg(fake_dir().join("requirements.txt")),
        "pip install of the official Spot SDK (needs PyPI)",
    )?;
    std::fs::write(&stamp, requirements).map_err(|e| format!("{}: {e}", stamp.display()))?;
    Ok(python)
}

/// A running fake Spot; killed on drop.
pub struct FakeSpot {
    pub child: Child,
    stdin: ChildStdin,
    lines: Receiver<String>,
    pub port: u16,
    pub dir: PathBuf,
}

/// Start a fake Spot with extra arguments (`--clock-offset 12.5`, `--token-lifetime 3`).
pub fn start(name: &str, args: &[&str]) -> FakeSpot {
    static SERIAL: Mutex<u32> = Mutex::new(0);
    let python = python();
    let serial = {
        let mut s = SERIAL.lock().unwrap();
        *s += 1;
        *s
    };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("fake-spot-{name}-{}-{serial}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut child = Command::new(python)
        .arg(fake_dir().join("fake_spot.py"))
        .arg("--dir")
        .arg(&dir)
        .args(["--username", USERNAME, "--password", PASSWORD])
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the fake Spot starts");
    let stdin = child.stdin.take().unwrap();
    let stdout = child.stdout.take().unwrap();
    let (send, lines) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    let ready = lines
        .recv_timeout(Duration::from_secs(60))
        .expect("the fake Spot prints READY <port> within 60 s");
    let port = ready
        .strip_prefix("READY ")
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("unexpected first line from the fake: {ready:?}"));
    FakeSpot {
        child,
        stdin,
        lines,
        port,
        dir,
    }
}

impl FakeSpot {
    /// The CA the fake made.
    pub fn ca_pem(&self) -> Vec<u8> {
        std::fs::read(self.dir.join("ca.pem")).unwrap()
    }

    /// A client configuration for this fake, with the right credentials.
    pub fn config(&self) -> SpotConfig {
        let mut config = SpotConfig::new(
            "127.0.0.1",
            self.ca_pem(),
            Credentials::new(USERNAME, PASSWORD),
        );
        config.port = self.port;
        config.call_timeout = Duration::from_secs(3);
        config
    }

    /// Send a control line (`take-lease`, `stall-time-sync`, `malformed-cloud`, `drop`) and
    /// wait for its acknowledgement.
    pub fn control(&mut self, line: &str) {
        writeln!(self.stdin, "{line}").unwrap();
        self.stdin.flush().unwrap();
        let ack = self.lines.recv_timeout(Duration::from_secs(10)).unwrap();
        assert_eq!(ack, format!("OK {line}"));
        if line == "drop" {
            let _ = self.child.wait();
        }
    }

    /// Send a control line and return what follows `OK <line>` in its answer.
    pub fn query(&mut self, line: &str) -> String {
        writeln!(self.stdin, "{line}").unwrap();
        self.stdin.flush().unwrap();
        let answer = self.lines.recv_timeout(Duration::from_secs(30)).unwrap();
        answer
            .strip_prefix(&format!("OK {line}"))
            .unwrap_or_else(|| panic!("unexpected answer to {line:?}: {answer:?}"))
            .trim()
            .to_owned()
    }

    /// Every request the fake decoded so far, in order.
    pub fn requests(&self) -> Vec<Value> {
        std::fs::read_to_string(self.dir.join("requests.jsonl"))
            .unwrap_or_default()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }

    /// The decoded requests of one method.
    pub fn requests_of(&self, method: &str) -> Vec<Value> {
        self.requests()
            .into_iter()
            .filter(|r| r["method"] == method)
            .collect()
    }
}

impl Drop for FakeSpot {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Run the official SDK's `fake_spot/sdk_flow.py` against `fake` with `extra` arguments; its
/// stdout, after checking it succeeded.
pub fn run_sdk_flow(fake: &FakeSpot, extra: &[&str]) -> Vec<u8> {
    let output = Command::new(python())
        .arg(fake_dir().join("sdk_flow.py"))
        .args(["--port", &fake.port.to_string(), "--ca"])
        .arg(fake.dir.join("ca.pem"))
        .args(["--username", USERNAME, "--password", PASSWORD])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output.stdout
}

/// A fake Spot for a test ([`start`]), with extra arguments when given.
#[macro_export]
macro_rules! fake_spot {
    ($name:expr) => {
        $crate::fake_spot!($name, &[])
    };
    ($name:expr, $args:expr) => {
        support::start($name, $args)
    };
}

/// The fake's known cloud (`known_points` of `fake_spot.py`).
pub fn known_points() -> Vec<[f32; 3]> {
    (0..120)
        .map(|i: u32| {
            let i = f64::from(i);
            // As Python packs its doubles: rounded to the nearest f32.
            [
                (0.05 * i) as f32,
                (-0.02 * i) as f32,
                (0.01 * (i % 7.0)) as f32,
            ]
        })
        .collect()
}

/// The fake's grid cell value (`grid_value` of `fake_spot.py`).
pub fn grid_value(x: u32, y: u32) -> f64 {
    if (x / 4 + y / 3).is_multiple_of(2) {
        f64::from((3 * x + 5 * y) % 11)
    } else {
        0.0
    }
}
