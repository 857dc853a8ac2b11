//! The Python package's tests: build the wheel with maturin, install it into a venv made on
//! first use under `target/tmp/py-spot-nav` (the packages of `tests/requirements.txt`), and run
//! pytest on `tests/*.py`.
//!
//! The wheel is built in release into the same target directory as the workspace, so the
//! dependencies that `cargo test --workspace --release` compiled are reused. A missing
//! `python3` or an unreachable package index fails the test with the reason; only an explicit

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn here() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Run `command`; its stderr (and stdout) in the error.
fn run(command: &mut Command, what: &str) -> Result<String, String> {
    let output = command
        .output()
        .map_err(|e| format!("{what}: cannot start: {e} (is python3 installed?)"))?;
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    if output.status.success() {
        Ok(stdout)
    } else {
        Err(format!(
            "{what} failed ({}):\n{stdout}\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ))
    }
}

/// The venv's python with the pinned requirements, made on first use.
fn venv() -> Result<PathBuf, String> {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("py-spot-nav");
    let python = venv.join("bin").join("python");
    let requirements = std::fs::read_to_string(here().join("tests/requirements.txt"))
        .map_err(|e| format!("tests/requirements.txt: {e}"))?;
    let stamp = venv.join("installed-requirements.txt");
    if python.exists() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == requirements) {
        return Ok(python);
    }
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
            .arg(here().join("tests/requirements.txt")),
        "pip install of maturin, numpy and pytest (needs PyPI)",
    )?;
    std::fs::write(&stamp, requirements).map_err(|e| format!("{}: {e}", stamp.display()))?;
    Ok(python)
}

#[test]
fn pytest_suite() {
    let started = Instant::now();
    let python = venv().unwrap_or_else(|e| panic!("the Python tests cannot run: {e}"));
    let bin = python.parent().unwrap();
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    // <target>/tmp: the workspace's target directory is its parent.
    let target = tmp.parent().unwrap();
    let wheels = tmp.join("py-spot-nav-wheels");
    let _ = std::fs::remove_dir_all(&wheels);
    let built = Instant::now();
    run(
        Command::new(bin.join("maturin"))
            .args(["build", "--release", "--quiet", "--interpreter"])
            .arg(&python)
            .arg("--manifest-path")
            .arg(here().join("Cargo.toml"))
            .arg("--target-dir")
            .arg(target)
            .arg("--out")
            .arg(&wheels)
            .env("VIRTUAL_ENV", python.parent().unwrap().parent().unwrap()),
        "maturin build",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let build_s = built.elapsed().as_secs_f64();
    let wheel = std::fs::read_dir(&wheels)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .expect("maturin wrote a wheel");
    run(
        Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "--no-deps",
                "--force-reinstall",
            ])
            .arg(&wheel),
        "pip install of the wheel",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let out = run(
        Command::new(&python)
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
            // Its temporary files under the target directory, not /tmp/pytest-of-<user>.
            .arg("--basetemp")
            .arg(tmp.join("pytest-basetemp"))
            .arg(here().join("tests"))
            .current_dir(here()),
        "pytest",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{out}");
    eprintln!(
        "python package: wheel built in {build_s:.1} s, everything in {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
