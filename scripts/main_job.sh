#!/usr/bin/env bash
# The main job, end to end on a fresh Debian 12 machine:
#   1. installs every missing Debian package (scripts/install_deps.sh),
#   2. configures and builds evio (Release),
#   3. runs the campaign experiments/campaigns/main.yaml: simulates the default
#      scenario (experiments/scenarios/mars_yard_circle.yaml: 10 s of a
#      hand-held DAVIS346 circling over the Mars-yard shadow edge) into a
#      complete sequence folder (events, frames, IMU, exact ground truth), runs
#      EKLT-VIO and KLT-VIO on it (`evio estimate`) and scores both
#      (`evio evaluate`, the paper's posyaw alignment on t0+3..8 s),
#   4. writes the report (`evio report`: Markdown and CSV tables, plots),
#      plots the sequence (trajectory, a frame with ground-truth tracks and
#      the events before it), writes its video (`evio video`: frames beside
#      events, ground-truth tracks) and summarises it with `evio info`,
#   5. prints the comparison table.
# Re-running resumes: finished jobs are kept (delete the folder to start over).
# Usage: scripts/main_job.sh [output-folder]   (default: out/main)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/main}
start=$(date +%s)

bash scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target evio
evio=build/release/bin/evio

echo "== campaign experiments/campaigns/main.yaml -> $out"
"$evio" campaign experiments/campaigns/main.yaml -o "$out" -j 2
echo "== report $out/report"
"$evio" report "$out" -q
sequence=$(ls -d "$out"/sequences/mars_yard_circle.*/seed-1 | head -n 1)
/usr/bin/python3 experiments/plots/plot_trajectory.py "$sequence"
/usr/bin/python3 experiments/plots/plot_sequence_preview.py "$sequence" --frame 100
echo "== evio video $sequence -> $out/report/sequence.mp4"
"$evio" video "$sequence" -o "$out/report/sequence.mp4" --speed 0.5 -q
echo "== evio info $sequence"
"$evio" info "$sequence"
echo
echo "== EKLT-VIO against KLT-VIO on mars_yard_circle ($out/report/report.md, figures beside it)"
sed -n '/^| method/,/^$/p' "$out/report/report.md"
echo "main job: $(( $(date +%s) - start )) s"
