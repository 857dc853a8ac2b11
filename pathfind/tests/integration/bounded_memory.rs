//! Moving AI headers that claim more cells than the file holds: parsed in a child process capped
//! at 1 GiB of address space (`ulimit -v`), because an allocation failure aborts the process and
//! cannot be caught. Before the fix a 43-byte header reserved 64 GiB of terrain letters.
#![cfg(unix)]
#![allow(clippy::unwrap_used, clippy::panic)]

use pathfind::PathfindError;
use pathfind::movingai::parse_map;

/// Set in the child: run the checks instead of spawning.
const CHILD: &str = "PATHFIND_BOUNDED_CHILD";

fn check_headers() {
    for (w, h) in [
        (262_144u32, 262_144u32),
        (65_536, 65_536),
        (4_000_000_000, 1),
    ] {
        let text = format!("type octile\nheight {h}\nwidth {w}\nmap\n.@.\n");
        match parse_map(&text) {
            Err(PathfindError::Parse { line: 4, message }) => {
                assert!(message.contains("only 4 bytes follow"), "{message}");
            }
            other => panic!("{w}x{h}: {other:?}"),
        }
    }
}

#[test]
fn huge_map_headers_are_refused_before_allocating() {
    if std::env::var_os(CHILD).is_some() {
        check_headers();
        return;
    }
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 1048576 && ulimit -t 20 && exec "$0" "$@""#)
        .arg(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "bounded_memory::huge_map_headers_are_refused_before_allocating",
        ])
        .args(["--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "capped child: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    // The filter must have found the test: a child that ran nothing would pass vacuously.
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("1 passed"),
        "the capped child ran no test: {}",
        String::from_utf8_lossy(&out.stdout)
    );
}
