#!/usr/bin/env bash
# GTSAM 4.x (PyPI wheel) LM beside spot-nav's LM on the posegraph bench files, in the same run:
# per file, GTSAM's best of five (in one process) and ours (the g2o example) best of five
# processes, and the ratio. torus3D: GTSAM from the file's guess and from its own chordal
# initialisation; ours from the chordal initialisation (its time included on both sides).
# Usage: bash benches/peers/gtsam_posegraph.sh [ROUNDS]   (SPOT_NAV_DATA overrides ../shared/data)
# ROUNDS (default 1) repeats the whole comparison and keeps each side's best: on a shared
# machine the load changes between runs.
set -euo pipefail
cd "$(dirname "$0")/../.."
data="${SPOT_NAV_DATA:-../shared/data}/posegraph"
rounds="${1:-1}"
venv=target/peers/gtsam-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q gtsam==4.3.0
fi
cargo build --release -q --example g2o
ours() {  # best of five wall times (ms) of our LM on $1 with extra arguments
    local file="$1"
    shift
    for _ in 1 2 3 4 5; do
        target/release/examples/g2o "$file" "$@" | awk '/^time/ {print $2}'
    done | sort -g | head -1
}
declare -A best_gtsam best_ours
for _ in $(seq "$rounds"); do
    for f in sphere2500 parking-garage input_M3500_g2o intel torus3D; do
        args=()
        peer="$data/$f.g2o"
        if [ "$f" = torus3D ]; then
            args=(--init chordal)
            peer="chordal:$data/$f.g2o"
        fi
        line=$(OMP_NUM_THREADS=1 "$venv/bin/python" benches/peers/gtsam_posegraph.py "$peer")
        echo "$line"
        g=${line##*ms=}
        o=$(ours "$data/$f.g2o" "${args[@]}")
        best_gtsam[$f]=$(printf '%s\n' "$g" "${best_gtsam[$f]:-$g}" | sort -g | head -1)
        best_ours[$f]=$(printf '%s\n' "$o" "${best_ours[$f]:-$o}" | sort -g | head -1)
    done
done
echo "file            GTSAM LM ms   our LM ms   speed-up"
for f in sphere2500 parking-garage input_M3500_g2o intel torus3D; do
    g=${best_gtsam[$f]}
    o=${best_ours[$f]}
    printf '%-15s %11s %11s %9.2fx\n' "$f" "$g" "$o" "$(echo "$g / $o" | bc -l)"
done
target/release/examples/g2o "$data/torus3D.g2o" --init chordal | grep -E "^(file|log-map|time)"
echo "GTSAM's LM on torus3D from the file's guess (a local minimum, one run):"
OMP_NUM_THREADS=1 "$venv/bin/python" benches/peers/gtsam_posegraph.py "$data/torus3D.g2o"
