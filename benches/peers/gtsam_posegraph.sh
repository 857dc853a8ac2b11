#!/usr/bin/env bash
# GTSAM 4.x (PyPI wheel) LM on the posegraph bench files, beside spot-nav's LM in the same run.
# torus3D: GTSAM's LM from the file's guess and from its own chordal initialisation; ours from
# the chordal initialisation.
# Usage: bash benches/peers/gtsam_posegraph.sh   (SPOT_NAV_DATA overrides ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/../.."
data="${SPOT_NAV_DATA:-../shared/data}/posegraph"
venv=target/peers/gtsam-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q gtsam
fi
OMP_NUM_THREADS=1 "$venv/bin/python" benches/peers/gtsam_posegraph.py \
    "$data/sphere2500.g2o" "$data/parking-garage.g2o" "$data/input_M3500_g2o.g2o" "$data/intel.g2o" \
    "$data/torus3D.g2o" "chordal:$data/torus3D.g2o"
for f in sphere2500.g2o parking-garage.g2o input_M3500_g2o.g2o intel.g2o; do
    cargo run --release -q --example g2o -- "$data/$f" | grep -E "^(file|log-map|time)"
done
cargo run --release -q --example g2o -- "$data/torus3D.g2o" --init chordal | grep -E "^(file|log-map|time)"
