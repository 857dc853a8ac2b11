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
"$venv/bin/python" benches/peers/small_gicp_registration.py \
    registration/tests/data/source.ply slam-core/tests/data/hdl32e_pair_target.ply \
    registration/tests/data/T_target_source.txt
cargo bench -p spot-nav-benches --bench registration -- PointToPlaneIcp/prepare_and_align 2>/dev/null | grep -E "prepare_and_align|time:"
