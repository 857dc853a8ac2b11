#!/usr/bin/env bash
# small_gicp 1.0.1 (PyPI) point-to-plane ICP on the HDL-32E pair, beside spot-nav's in the same run.
# Usage: bash benches/peers/small_gicp_registration.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/peers/small-gicp-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q small_gicp==1.0.1 numpy
fi
peer=$("$venv/bin/python" benches/peers/small_gicp_registration.py \
    registration/tests/data/source.ply slam-core/tests/data/hdl32e_pair_target.ply \
    registration/tests/data/T_target_source.txt)
echo "$peer"
# Ours on the same files and settings (the example's defaults: the bundled pair, 0.25 m voxels).
cargo build -q --release -p spot-nav-examples --example register
ours=$(target/release/examples/register --repeat 20)
echo "$ours" | grep -E "^(time|vs reference)"
# Both best-of-20 and both medians, so the ratio compares like with like.
read -r peer_best peer_median < <(echo "$peer" | sed -E 's/.*best ([0-9.]+) ms, median ([0-9.]+) ms.*/\1 \2/')
read -r our_best our_median < <(echo "$ours" | grep "^time" | sed -E 's/.*best ([0-9.]+) ms, median ([0-9.]+) ms.*/\1 \2/')
awk -v pb="$peer_best" -v pm="$peer_median" -v ob="$our_best" -v om="$our_median" \
    'BEGIN { printf "ours / small_gicp: best %.2f, median %.2f\n", ob / pb, om / pm }'
