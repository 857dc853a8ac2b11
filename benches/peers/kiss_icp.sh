#!/usr/bin/env bash
# KISS-ICP 1.3.0 (PyPI) beside spot-nav's LiDAR-only `slam` on the same folder of scans, in the
# same run, both against the same ground truth with the same code (kiss_icp_peer.py's `evaluate`,
# checked first against evo's and the KITTI devkit's golden figures in
# spot-adapter/tests/data/evo, and printed beside our own Rust evaluation of our trajectory).
#
# Usage: bash benches/peers/kiss_icp.sh SCANS_DIR GROUND_TRUTH [extra slam args]
#   SCANS_DIR     PCD or PLY scans, one a file, named by their stamps (seconds)
#   GROUND_TRUTH  TUM (stamp tx ty tz qx qy qz qw) or KITTI poses (12 numbers, one line a scan)
#                 of the body (= the LiDAR unless the extra args give --calibration)
# KISS-ICP runs with its defaults; KISS_MAX_RANGE (m; its voxel then follows, max_range / 100),
# KISS_VOXEL_SIZE (m) and KISS_THREADS (0 = all cores, its default) change them. KISS_RUNS (default
# 1) runs both that many times, one after the other, and ends with each run's means and the median
# ratio: a shared machine's timings vary from run to run by more than most changes. Prints end-point
# drift, ATE, RPE per 100 m, height drift, steps with more than 2 and 5 degrees of rotation error,
# mean and p99 ms a scan (ours: the engine's, from summary.json, the whole LiDAR-only front end;
# KISS-ICP: register_frame alone) and the ratio of the means. Installs kiss-icp into target/peers
# and leaves both trajectories in target/peers/kiss-icp-out.
set -euo pipefail
if [ $# -lt 2 ]; then
    sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
runs="${KISS_RUNS:-1}"
if ! [[ "$runs" =~ ^[1-9][0-9]*$ ]]; then
    echo "KISS_RUNS must be a positive whole number, not '$runs'" >&2
    exit 2
fi
scans=$(realpath "$1")
truth=$(realpath "$2")
shift 2
cd "$(dirname "$0")/../.."
venv=target/peers/kiss-icp-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -c "import kiss_icp" 2>/dev/null || "$venv/bin/pip" install -q kiss-icp==1.3.0
"$venv/bin/python" benches/peers/kiss_icp_peer.py --selftest spot-adapter/tests/data/evo
cargo build -q --release -p spot-nav-examples --example slam
slam="${CARGO_TARGET_DIR:-target}/release/examples/slam"
# What both wrote stays for a look: ours/ (slam --out), kiss_icp.tum (KISS-ICP's body poses).
work=target/peers/kiss-icp-out
rm -rf "$work"
mkdir -p "$work"
kiss_args=()
[ -n "${KISS_MAX_RANGE:-}" ] && kiss_args+=(--max-range "$KISS_MAX_RANGE")
[ -n "${KISS_VOXEL_SIZE:-}" ] && kiss_args+=(--voxel-size "$KISS_VOXEL_SIZE")
[ -n "${KISS_THREADS:-}" ] && kiss_args+=(--threads "$KISS_THREADS")
# Our trajectory is the body's: KISS-ICP's (the LiDAR's) is moved by the same calibration.
calibration=""
previous=""
for a in "$@"; do
    [ "$previous" = "--calibration" ] && calibration="$a"
    case "$a" in --calibration=*) calibration="${a#--calibration=}" ;; esac
    previous="$a"
done
[ -n "$calibration" ] && kiss_args+=(--calibration "$calibration")
summary=()
for run in $(seq "$runs"); do
    [ "$runs" -gt 1 ] && echo "== run $run of $runs"
    rm -rf "$work/ours"
    echo "== ours: slam $scans --no-odometry --ground-truth $truth $*"
    "$slam" "$scans" --no-odometry --ground-truth "$truth" --out "$work/ours" "$@"
    echo "== KISS-ICP 1.3.0 and both against the ground truth"
    out=$("$venv/bin/python" benches/peers/kiss_icp_peer.py "$scans" "$truth" "$work/ours" \
        --write-tum "$work/kiss_icp.tum" "${kiss_args[@]}")
    echo "$out"
    means=$(echo "$out" | sed -n 's|^mean / p99 ms a scan *\([0-9.]*\) / [0-9.]* (engine) *\([0-9.]*\) / .*|\1 \2|p')
    if [ -z "$means" ]; then
        echo "could not read both mean times a scan from the comparison above" >&2
        exit 1
    fi
    summary+=("$means")
done
if [ "$runs" -gt 1 ]; then
    echo "== $runs runs: ours / KISS-ICP mean ms a scan, and the ratio"
    printf '%s\n' "${summary[@]}" | awk '{ printf "run %d    %.2f / %.2f ms    %.3f\n", NR, $1, $2, $1 / $2 }'
    printf '%s\n' "${summary[@]}" | awk '{ print $1 / $2 }' | sort -g | awk '
        { r[NR] = $1 }
        END {
            m = (NR % 2) ? r[(NR + 1) / 2] : (r[NR / 2] + r[NR / 2 + 1]) / 2
            printf "median ratio %.3f (of %d runs; lowest %.3f, highest %.3f)\n", m, NR, r[1], r[NR]
        }'
fi
