#!/usr/bin/env bash
# small_gicp 1.0.1 (PyPI) point-to-plane ICP on the HDL-32E pair, beside spot-nav's in the same run.
# Usage: bash benches/peers/small_gicp_registration.sh
# Prints the two times run in turns, then both sides' errors against exact ground truth (random
# halves of a real scan, one moved by a known transform: small_gicp_halves.py).
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/peers/small-gicp-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q small_gicp==1.0.1 numpy
fi
# The machine's speed drifts over minutes (a shared VM), so the two run in turns: ROUNDS rounds
# (default 5) of 4 runs each, small_gicp then ours. Ratios compare the best run of each, and the
# median of each side's round medians.
cargo build -q --release -p spot-nav-examples --example register
rounds=${ROUNDS:-5}
peer_bests=(); peer_medians=(); our_bests=(); our_medians=()
for _ in $(seq "$rounds"); do
    peer=$("$venv/bin/python" benches/peers/small_gicp_registration.py \
        registration/tests/data/source.ply slam-core/tests/data/hdl32e_pair_target.ply \
        registration/tests/data/T_target_source.txt 4)
    # Ours on the same files and settings (the example's defaults: the bundled pair, 0.25 m).
    ours=$(target/release/examples/register --repeat 4)
    echo "$peer"
    echo "$ours" | grep -E "^time"
    read -r b m < <(echo "$peer" | sed -E 's/.*best ([0-9.]+) ms, median ([0-9.]+) ms.*/\1 \2/')
    peer_bests+=("$b"); peer_medians+=("$m")
    read -r b m < <(echo "$ours" | grep "^time" | sed -E 's/.*best ([0-9.]+) ms, median ([0-9.]+) ms.*/\1 \2/')
    our_bests+=("$b"); our_medians+=("$m")
done
echo "$ours" | grep -E "^vs reference"
min() { printf '%s\n' "$@" | sort -g | head -1; }
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
pb=$(min "${peer_bests[@]}"); pm=$(median "${peer_medians[@]}")
ob=$(min "${our_bests[@]}"); om=$(median "${our_medians[@]}")
echo "small_gicp: best $pb ms, median of round medians $pm ms; ours: best $ob ms, median $om ms"
awk -v pb="$pb" -v pm="$pm" -v ob="$ob" -v om="$om" \
    'BEGIN { printf "ours / small_gicp: best %.2f, median %.2f\n", ob / pb, om / pm }'
work=$(mktemp -d)
"$venv/bin/python" benches/peers/small_gicp_halves.py \
    slam-core/tests/data/hdl32e_pair_target.ply target/release/examples/register "$work"
rm -rf "$work"
