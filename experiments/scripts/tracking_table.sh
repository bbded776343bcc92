#!/usr/bin/env bash
# Feature-tracking table of issue 6: simulates 10 s of poster_6dof,
# shapes_6dof and mars_yard_circle (plus mars_yard_circle with the frame
# camera over- and under-exposed), runs EKLT on frames, EKLT on reconstructed
# images and KLT (`evio track`), scores every track against the truth from
# the depth maps and poses (`evio evaluate-tracks`, depth mode) and prints a
# markdown table.
#
#   experiments/scripts/tracking_table.sh [--evio build/release/bin/evio] [--out out/tracking]
#                                         [--depth-time-tolerance 0.03] [--only NAME]
#
# Sequences and results are kept under --out; a step whose output exists is
# not run again (delete the folder to redo it). Runs one process at a time.
#
# Exposure variants (frame camera only; the events are the same): auto-exposure
# and first-frame metering off, a fixed exposure of
#   overexposed:  1e-3 s  (about 2x what auto-exposure picks in the shadow,
#                          about 30x in the sunlit sand: sunlit half blown out)
#   underexposed: 2e-5 s  (about 1/27 of the shadow's auto-exposure: the
#                          shadow is 0-5 DN, the sunlit sand about 40 DN)
set -euo pipefail
cd "$(dirname "$0")/../.."
EVIO=build/release/bin/evio
OUT=out/tracking
TOL=0.03
ONLY=""
while [ $# -gt 0 ]; do
  case "$1" in
    --evio) EVIO="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --depth-time-tolerance) TOL="$2"; shift 2 ;;
    --only) ONLY="$2"; shift 2 ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -x "$EVIO" ] || { echo "no evio binary at $EVIO (--evio)" >&2; exit 2; }
mkdir -p "$OUT"
FIXED="--set rig.frame_camera.sensor.auto_exposure=false --set rig.frame_camera.meter_first_exposure=false"
declare -A SIM=(
  [poster_6dof]="experiments/scenarios/poster_6dof.yaml --set duration_s=10"
  [shapes_6dof]="experiments/scenarios/shapes_6dof.yaml --set duration_s=10"
  [mars_yard_circle]="experiments/scenarios/mars_yard_circle.yaml --set duration_s=10 --set trajectory.duration_s=10"
  [mars_yard_circle_overexposed]="experiments/scenarios/mars_yard_circle.yaml --set duration_s=10 --set trajectory.duration_s=10 $FIXED --set rig.frame_camera.sensor.exposure_s=1e-3 --set output.write_events_txt=false"
  [mars_yard_circle_underexposed]="experiments/scenarios/mars_yard_circle.yaml --set duration_s=10 --set trajectory.duration_s=10 $FIXED --set rig.frame_camera.sensor.exposure_s=2e-5 --set output.write_events_txt=false"
)
SEQS="poster_6dof shapes_6dof mars_yard_circle mars_yard_circle_overexposed mars_yard_circle_underexposed"
METHODS="eklt_frames eklt_reconstructed klt"
for s in $SEQS; do
  [ -n "$ONLY" ] && [ "$ONLY" != "$s" ] && continue
  seq="$OUT/$s"
  if [ ! -f "$seq/simulation_stats.yaml" ]; then
    echo "simulating $s" >&2
    # shellcheck disable=SC2086
    "$EVIO" simulate ${SIM[$s]} -o "$seq" --threads 1 -q
  fi
  for m in $METHODS; do
    tracks="$OUT/${s}_$m.txt"
    case $m in
      eklt_frames) args="--frontend eklt --image-source frames" ;;
      eklt_reconstructed) args="--frontend eklt --image-source reconstructed" ;;
      klt) args="--frontend klt --image-source frames" ;;
    esac
    if [ ! -f "$tracks" ]; then
      echo "tracking $s with $m" >&2
      # shellcheck disable=SC2086
      "$EVIO" track "$seq" $args -o "$tracks" -q
    fi
    "$EVIO" evaluate-tracks "$tracks" "$seq" --mode depth --depth-time-tolerance "$TOL" \
      -o "$OUT/${s}_$m.json" -q
  done
done

python3 - "$OUT" "$SEQS" "$METHODS" <<'PY'
import json, os, sys
out, seqs, methods = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
names = {"eklt_frames": "EKLT (frames)", "eklt_reconstructed": "EKLT (reconstructed)", "klt": "KLT"}
def at_age(m, age):
    for b in m["error_vs_age"]:
        if abs(b["age_s"] - age) < 1e-9:
            return "%.2f (%d)" % (b["mean_error_px"], b["samples"])
    return "–"
print("| sequence | tracker | tracks | evaluable | error mean / median (px) | age mean / median (s) "
      "| ended by error / truth / track | error at age 0.1 / 0.5 / 1.0 s, px (samples) |")
print("|---|---|---:|---:|---|---|---|---|")
for s in seqs:
    for k in methods:
        p = os.path.join(out, "%s_%s.json" % (s, k))
        if not os.path.exists(p):
            continue
        m = json.load(open(p))
        print("| %s | %s | %d | %d | %.2f / %.2f | %.3f / %.3f | %d / %d / %d | %s / %s / %s |" % (
            s, names[k], m["estimated_tracks"], m["matched_tracks"], m["mean_error_px"], m["median_error_px"],
            m["mean_feature_age_s"], m["median_feature_age_s"], m["ended_by_error"], m["ended_by_truth"],
            m["ended_by_track"], at_age(m, 0.1), at_age(m, 0.5), at_age(m, 1.0)))
PY
