#!/usr/bin/env bash
# Feature-tracking table of issue 6: simulates 10 s of poster_6dof,
# shapes_6dof and mars_yard_circle (plus mars_yard_circle with the frame
# camera over- and under-exposed), runs EKLT on frames, EKLT on reconstructed
# images, KLT and HASTE seeded on frames and on reconstructed images (`evio track`), scores every track against the truth from
# the depth maps and poses (`evio evaluate-tracks`, depth mode) and prints a
# markdown table; a second table scores the same tracks with a 1 px error
# bound (how long they stay sub-pixel), a third gives the frames' motion blur.
#
#   experiments/scripts/tracking_table.sh [--evio build/release/bin/evio] [--out out/tracking]
#                                         [--depth-time-tolerance 0.03] [--only NAME]
#                                         [--methods "eklt_frames eklt_reconstructed klt haste_frames haste_reconstructed"]
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
#
# Fast rows (*_fast): the 6-DOF one-minute speed ramp compressed into 12 s
# (trajectory.duration_s=12, as experiments/campaigns/paper_table.yaml),
# simulated only from 6 s to 12 s (the faster half: image speed median about
# 500 px/s, 90 % about 900 px/s) to save time; frame camera as configured
# (auto-exposure picks 0.1-0.2 ms: blur below 0.4 px).
# *_fast_long: fixed 15 ms exposure with the lens stopped down from f/4 to
# f/32 (poster, 1/64 of the light) or f/45 (shapes, 1/127), the same photon
# count as a 64x / 127x dimmer room (mean 150 / 114 DN, 3 % / 0 % at 255),
# and 16 renders per exposure instead of 3 so the 7-21 px blur is rendered in
# steps of at most 1.4 px. The extra renders also update the event camera,
# so its events differ slightly from *_fast.
set -euo pipefail
cd "$(dirname "$0")/../.."
EVIO=build/release/bin/evio
OUT=out/tracking
TOL=0.03
ONLY=""
METHODS="eklt_frames eklt_reconstructed klt haste_frames haste_reconstructed"
while [ $# -gt 0 ]; do
  case "$1" in
    --evio) EVIO="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --depth-time-tolerance) TOL="$2"; shift 2 ;;
    --only) ONLY="$2"; shift 2 ;;
    --methods) METHODS="$2"; shift 2 ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -x "$EVIO" ] || { echo "no evio binary at $EVIO (--evio)" >&2; exit 2; }
mkdir -p "$OUT"
FIXED="--set rig.frame_camera.sensor.auto_exposure=false --set rig.frame_camera.meter_first_exposure=false"
FAST="--set trajectory.duration_s=12 --set start_s=6 --set duration_s=6 --set output.write_events_txt=false"
declare -A SIM=(
  [poster_6dof]="experiments/scenarios/poster_6dof.yaml --set duration_s=10"
  [shapes_6dof]="experiments/scenarios/shapes_6dof.yaml --set duration_s=10"
  [mars_yard_circle]="experiments/scenarios/mars_yard_circle.yaml --set duration_s=10 --set trajectory.duration_s=10"
  [mars_yard_circle_overexposed]="experiments/scenarios/mars_yard_circle.yaml --set duration_s=10 --set trajectory.duration_s=10 $FIXED --set rig.frame_camera.sensor.exposure_s=1e-3 --set output.write_events_txt=false"
  [mars_yard_circle_underexposed]="experiments/scenarios/mars_yard_circle.yaml --set duration_s=10 --set trajectory.duration_s=10 $FIXED --set rig.frame_camera.sensor.exposure_s=2e-5 --set output.write_events_txt=false"
  [poster_6dof_fast]="experiments/scenarios/poster_6dof.yaml $FAST"
  [poster_6dof_fast_long]="experiments/scenarios/poster_6dof.yaml $FAST $FIXED --set rig.frame_camera.sensor.exposure_s=0.015 --set rig.frame_camera.sensor.f_number=32 --set rig.frame_camera.exposure_samples=16"
  [shapes_6dof_fast]="experiments/scenarios/shapes_6dof.yaml $FAST"
  [shapes_6dof_fast_long]="experiments/scenarios/shapes_6dof.yaml $FAST $FIXED --set rig.frame_camera.sensor.exposure_s=0.015 --set rig.frame_camera.sensor.f_number=45 --set rig.frame_camera.exposure_samples=16"
)
SEQS="poster_6dof shapes_6dof mars_yard_circle mars_yard_circle_overexposed mars_yard_circle_underexposed
      poster_6dof_fast poster_6dof_fast_long shapes_6dof_fast shapes_6dof_fast_long"
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
      haste_frames) args="--frontend haste --image-source frames" ;;
      haste_reconstructed) args="--frontend haste --image-source reconstructed" ;;
    esac
    if [ ! -f "$tracks" ]; then
      echo "tracking $s with $m" >&2
      # shellcheck disable=SC2086
      "$EVIO" track "$seq" $args -o "$tracks" -q
    fi
    "$EVIO" evaluate-tracks "$tracks" "$seq" --mode depth --depth-time-tolerance "$TOL" \
      -o "$OUT/${s}_$m.json" -q
    # the same with a 1 px error bound: how long tracks stay sub-pixel
    "$EVIO" evaluate-tracks "$tracks" "$seq" --mode depth --depth-time-tolerance "$TOL" \
      --max-error 1 -o "$OUT/${s}_${m}_1px.json" -q
  done
done

/usr/bin/python3 - "$OUT" "$SEQS" "$METHODS" <<'PY'
import json, os, sys
out, seqs, methods = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
names = {"eklt_frames": "EKLT (frames)", "eklt_reconstructed": "EKLT (reconstructed)", "klt": "KLT",
         "haste_frames": "HASTE (frames)", "haste_reconstructed": "HASTE (reconstructed)"}
def at_age(m, age):
    for b in m["error_vs_age"]:
        if abs(b["age_s"] - age) < 1e-9:
            return "%.2f (%d)" % (b["mean_error_px"], b["samples"])
    return "–"
print("| sequence | tracker | tracks | evaluable | error mean / median (px) | age mean / median (s) "
      "| ended by error / truth / track | error at age 0.1 / 0.5 / 1.0 s, px (samples) |")
print("|---|---|---:|---:|---|---|---|---|")
def results(suffix):
    """(sequence, tracker name, metrics) of every evaluated sequence × method."""
    for s in seqs:
        for k in methods:
            p = os.path.join(out, "%s_%s%s.json" % (s, k, suffix))
            if os.path.exists(p):
                yield s, names[k], json.load(open(p))
for s, name, m in results(""):
    print("| %s | %s | %d | %d | %.2f / %.2f | %.3f / %.3f | %d / %d / %d | %s / %s / %s |" % (
        s, name, m["estimated_tracks"], m["matched_tracks"], m["mean_error_px"], m["median_error_px"],
        m["mean_feature_age_s"], m["median_feature_age_s"], m["ended_by_error"], m["ended_by_truth"],
        m["ended_by_track"], at_age(m, 0.1), at_age(m, 0.5), at_age(m, 1.0)))
print()
print("| sequence | tracker | sub-pixel age (until error > 1 px) mean / median (s) | ended by error / truth / track |")
print("|---|---|---|---|")
for s, name, m in results("_1px"):
    print("| %s | %s | %.3f / %.3f | %d / %d / %d |" % (
        s, name, m["mean_feature_age_s"], m["median_feature_age_s"], m["ended_by_error"],
        m["ended_by_truth"], m["ended_by_track"]))
PY

# Motion blur of the frames: exposure of frame k = 2 (stamp_k − start − k / rate)
# (stamps are mid-exposure), image speed from truth/tracks.txt (ground-truth
# point tracks, central differences at 200 Hz) at the track samples nearest
# each frame stamp, blur length = speed × exposure.
/usr/bin/python3 - "$OUT" "$SEQS" <<'PY'
import bisect, math, os, sys, yaml
from collections import defaultdict
out, seqs = sys.argv[1], sys.argv[2].split()
def q(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p * len(v)))] if v else float("nan")
print()
print("| sequence | exposure median (ms) | image speed at frame stamps median / p90 / max (px/s) "
      "| blur length median / p90 / max (px) |")
print("|---|---|---|---|")
for s in seqs:
    d = os.path.join(out, s)
    if not os.path.exists(os.path.join(d, "truth", "tracks.txt")):
        continue
    sc = yaml.safe_load(open(os.path.join(d, "scenario.yaml")))
    start, rate = float(sc["start_s"]), float(sc["rig"]["frame_camera"]["rate_hz"])
    frames = [float(l.split()[0]) for l in open(os.path.join(d, "images.txt")) if l.strip() and l[0] != "#"]
    exposure = [2.0 * (t - start - k / rate) for k, t in enumerate(frames)]
    tracks = defaultdict(list)
    for l in open(os.path.join(d, "truth", "tracks.txt")):
        if l[0] == "#":
            continue
        i, t, x, y = l.split()
        tracks[i].append((float(t), float(x), float(y)))
    speed = defaultdict(list)  # frame index -> speeds
    for samples in tracks.values():
        ts = [p[0] for p in samples]
        for k, tf in enumerate(frames):
            j = bisect.bisect_left(ts, tf)
            for c in (j - 1, j):
                if 1 <= c < len(samples) - 1 and abs(ts[c] - tf) <= 0.0026 and ts[c + 1] - ts[c - 1] < 0.011:
                    a, b = samples[c - 1], samples[c + 1]
                    speed[k].append(math.hypot(b[1] - a[1], b[2] - a[2]) / (b[0] - a[0]))
                    break
    sp = [v for k in speed for v in speed[k]]
    blur = [v * exposure[k] for k in speed for v in speed[k]]
    print("| %s | %.3f | %.0f / %.0f / %.0f | %.2f / %.2f / %.2f |" % (
        s, 1e3 * q(exposure, 0.5), q(sp, 0.5), q(sp, 0.9), max(sp), q(blur, 0.5), q(blur, 0.9), max(blur)))
PY
