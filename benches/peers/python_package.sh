#!/usr/bin/env bash
# spot_nav (the Python package, python/) beside small_gicp 1.0.1 and KISS-ICP 1.3.0 from Python,
# in the same process on the same arrays: python_package.py.
# Usage: bash benches/peers/python_package.sh [SCANS_DIR]
#   SCANS_DIR  PCD or PLY scans named by their stamps for the SLAM comparison; default:
#              $SPOT_NAV_DATA/lidar/hdl32e_garage_seq (SPOT_NAV_DATA defaults to ../shared/data
#              beside the workspace). Without it the SLAM part prints a notice and is skipped.
# Installs both peers and `pip install ./python` (a release build) into target/peers/python-venv.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/peers/python-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -c "import small_gicp, kiss_icp" 2>/dev/null \
    || "$venv/bin/pip" install -q small_gicp==1.0.1 kiss-icp==1.3.0 numpy==2.4.6
# The package as a user installs it from a clone (maturin builds it in release).
"$venv/bin/pip" install -q --disable-pip-version-check --force-reinstall --no-deps ./python
data=${SPOT_NAV_DATA:-$(realpath -m ../shared/data)}
scans=${1:-$data/lidar/hdl32e_garage_seq}
"$venv/bin/python" benches/peers/python_package.py \
    --source registration/tests/data/source.ply \
    --target slam-core/tests/data/hdl32e_pair_target.ply \
    --reference registration/tests/data/T_target_source.txt \
    --scans "$scans" "${@:2}"
