#!/usr/bin/env bash
# The online lag estimate (frontend.track_lag) on sequences whose delay is
# known exactly: the same 6 s of poster_6dof simulated twice, once with an
# ideal photoreceptor and once with a first-order low-pass of a fixed
# 100 Hz cut-off (time constant 1/(2π·100 Hz) = 1.592 ms, the radiance
# bandwidth model with equal floor and ceiling, no source follower). A
# first-order filter delays a ramp by exactly its time constant, so the
# estimated τ must grow by 1.592 ms (within 0.3 ms; measured 1.68 ms) and
# the distance part a must not change (within 0.1 px; measured 0.32 and
# 0.31 px). EKLT-VIO from ground truth; the estimates are read from each
# estimate's summary.yaml (track_lag).
#
# usage: track_lag_known_delay_test.sh <evio> <scenario.yaml> <estimator config> <work-folder>
set -euo pipefail
evio=$1
scenario=$2
config=$3
work=$4
rm -rf "$work"
mkdir -p "$work"
ec=rig.event_camera.event_camera
common=(--set seed=21 --set duration_s=6 --set trajectory.duration_s=12 --set output.write_events_txt=false
        --set output.depth_at_frames=false --set output.truth_tracks=0 --set "$ec.bandwidth_model=radiance"
        --set "$ec.source_follower_hz=0")
"$evio" simulate "$scenario" "${common[@]}" --set "$ec.cutoff_max_hz=0" -q -o "$work/ideal"
"$evio" simulate "$scenario" "${common[@]}" --set "$ec.cutoff_max_hz=100" --set "$ec.cutoff_min_hz=100" -q \
  -o "$work/delayed"
for s in ideal delayed; do
  "$evio" estimate "$work/$s" --method eklt-vio --init groundtruth --config "$config" -q -o "$work/est_$s"
done

# The value of key $2 in the track_lag map of summary.yaml $1.
lag() { awk -v key="$2" '/^track_lag:/ {m = 1; next} m && /^[^ ]/ {m = 0} m && $1 == key ":" {print $2}' "$1"; }
a0=$(lag "$work/est_ideal/summary.yaml" a_px)
t0=$(lag "$work/est_ideal/summary.yaml" tau_s)
a1=$(lag "$work/est_delayed/summary.yaml" a_px)
t1=$(lag "$work/est_delayed/summary.yaml" tau_s)
[ -n "$a0" ] && [ -n "$t0" ] && [ -n "$a1" ] && [ -n "$t1" ] || { echo "FAIL: no track_lag in a summary.yaml"; exit 1; }
awk -v a0="$a0" -v t0="$t0" -v a1="$a1" -v t1="$t1" 'BEGIN {
  expected = 1.0 / (2.0 * 3.141592653589793 * 100.0)
  dt = t1 - t0; da = a1 - a0
  printf "ideal: a %.3f px, tau %.3f ms; 100 Hz delay: a %.3f px, tau %.3f ms; tau grew %.3f ms (expected %.3f)\n",
         a0, 1e3 * t0, a1, 1e3 * t1, 1e3 * dt, 1e3 * expected
  ok = (dt - expected < 3e-4 && expected - dt < 3e-4 && da < 0.1 && -da < 0.1)
  if (!ok) { print "FAIL"; exit 1 }
  print "PASS"
}'
