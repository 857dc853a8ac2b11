#!/usr/bin/env bash
# GTSAM 4.3's graduated non-convexity (GncOptimizer, TLS over LM; PyPI wheel, one thread) beside
# spot-nav's GraduatedNonConvexity on the same corrupted graphs: the posegraph_robust bench writes
# them (ring.g2o + 2/5/13/45 wrong loops, input_M3500_g2o + 272, sphere2500 + 495; seeds 1-3) and
# prints our figures (best of POSEGRAPH_ROBUST_REPEATS, default 3); gtsam_gnc.py then runs GTSAM on
# each file with its default weight tolerance (1e-4) and with 1e-8 (best of three, one run past 5 s).
# Usage: bash benches/peers/gtsam_gnc.sh [CASES]   (CASES: comma-separated from ring,m3500,sphere;
# default all. SPOT_NAV_DATA overrides ../shared/data.) Takes about 20-30 minutes with sphere2500.
set -euo pipefail
cd "$(dirname "$0")/../.."
data="${SPOT_NAV_DATA:-../shared/data}/posegraph"
cases="${1:-ring,m3500,sphere}"
venv=target/peers/gtsam-venv
out="$PWD/target/peers/robust"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -c "import gtsam" 2>/dev/null || "$venv/bin/pip" install -q gtsam==4.3.0
mkdir -p "$out"
echo "== ours (cargo bench -p spot-nav-benches --bench posegraph_robust)"
POSEGRAPH_ROBUST_CASES="$cases" POSEGRAPH_ROBUST_WRITE="$out" \
    cargo bench -q -p spot-nav-benches --bench posegraph_robust
echo "== GTSAM GncOptimizer TLS"
args=()
for c in ${cases//,/ }; do
    case "$c" in
        ring) clean=ring; counts="2 5 13 45" ;;
        m3500) clean=input_M3500_g2o; counts="272" ;;
        sphere) clean=sphere2500; counts="495" ;;
        *) echo "unknown case $c" >&2; exit 2 ;;
    esac
    for n in $counts; do
        for s in 1 2 3; do
            args+=("$data/$clean.g2o:$out/${clean}_w${n}_s${s}.g2o:$n")
        done
    done
done
OMP_NUM_THREADS=1 "$venv/bin/python" benches/peers/gtsam_gnc.py "${args[@]}"
