#!/usr/bin/env bash
# The main job, end to end on a fresh Debian 12 machine. What it does grows
# with the project; today (see README "Status"):
#   1. installs every missing Debian package (scripts/install_deps.sh),
#   2. configures and builds evio (Release),
#   3. simulates the default scenario (experiments/scenarios/mars_yard_circle.yaml:
#      10 s of a hand-held DAVIS346 circling over the Mars-yard shadow edge) into
#      a complete sequence folder: events, frames, IMU, exact ground truth,
#   4. plots its trajectory and a preview (a frame with the ground-truth tracks,
#      and the events before it),
#   5. summarises the output folder with `evio info`.
# Estimating with EKLT-VIO and KLT-VIO, scoring and the report are added by
# the estimator and experiments issues.
# Usage: scripts/main_job.sh [output-folder]   (default: out/main)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/main}

bash scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target evio
evio=build/release/bin/evio

mkdir -p "$out"
echo "== simulate: experiments/scenarios/mars_yard_circle.yaml"
"$evio" simulate experiments/scenarios/mars_yard_circle.yaml -o "$out/sequence"
/usr/bin/python3 experiments/plots/plot_trajectory.py "$out/sequence" || echo "(trajectory plot failed; see above)"
/usr/bin/python3 experiments/plots/plot_sequence_preview.py "$out/sequence" --frame 100 || echo "(preview failed; see above)"
echo "== evio info $out/sequence"
"$evio" info "$out/sequence"
