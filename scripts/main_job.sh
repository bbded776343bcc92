#!/usr/bin/env bash
# The main job, end to end on a fresh Debian 12 machine. What it does grows
# with the project; today (see README "Status"):
#   1. installs every missing Debian package (scripts/install_deps.sh),
#   2. configures and builds evio (Release),
#   3. writes the default scenario's trajectory and IMU with exact ground truth
#      (trajectories/presets/circle.yaml: the Mars-yard hand-held circle) and
#      plots it,
#   4. renders a preview of the default scene (mars_yard) when the renderer is built,
#   5. summarises the output folder with `evio info`.
# Simulating events/frames, estimating with EKLT-VIO and KLT-VIO, scoring and
# the report are added by the simulator, estimator and experiments issues.
# Usage: scripts/main_job.sh [output-folder]   (default: out/main)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/main}

bash scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target evio
evio=build/release/bin/evio

mkdir -p "$out"
echo "== trajectory: Mars-yard circle (trajectories/presets/circle.yaml)"
"$evio" trajectory trajectories/presets/circle.yaml -o "$out/sequence"
if "$evio" render --help >/dev/null 2>&1 && [ -f scenes/presets/mars_yard.yaml ]; then
  echo "== render: a preview of scenes/presets/mars_yard.yaml"
  "$evio" render scenes/presets/mars_yard.yaml -o "$out/render" || echo "(render failed; see above)"
fi
echo "== evio info $out/sequence"
"$evio" info "$out/sequence"
