#!/usr/bin/env bash
# Event-count accuracy of the render schedules on every shipped scenario
# (README "Simulation (issue 5)"): a short window of each scenario simulated
#   ref    whole frames every 20 us (sampling at a fixed 50 kHz, q = 1),
#   whole  the scenario's whole-frame schedule (sampling.schedule=whole_frame),
#   tiles  the tile schedule (sampling.schedule=tiles) at the scenario's rates,
# once with the ideal pixel (no refractory period, no background-activity
# filter: the count is the number of threshold crossings) and once with the
# shipped sensor; noise off and no frames in both (frames would add whole
# renders), and prints one Markdown row per scenario with the counts and the
# differences from the reference.
#   scripts/tile_accuracy.sh [build-dir] [window-s]      (default: build/release 0.05)
# Windows start at t = 20 s (mars_yard_circle, 10 s long: at t = 6 s).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/release}"
window="${2:-0.05}"
evio="$build/bin/evio"
[ -x "$evio" ] || { echo "tile_accuracy: $evio not found (build the 'evio' target first)" >&2; exit 1; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "window: ${window} s; ideal pixel = refractory 0, BA filter off; noise off, frames off"
echo
echo "| scenario | ideal: ref events | whole | tiles | shipped sensor: ref events | whole | tiles | render equivalents / sim s: ref, whole, tiles |"
echo "|---|---:|---:|---:|---:|---:|---:|---|"
quiet=(--set output.write_events_txt=false --set rig.frame_camera.enabled=false --set output.truth_tracks=0
       --set rig.event_camera.event_camera.leak_rate_hz=0 --set rig.event_camera.event_camera.shot_noise_rate_hz=0
       --set rig.event_camera.event_camera.hot_pixel_fraction=0)
ideal=(--set rig.event_camera.event_camera.refractory_period_s=0 --set rig.event_camera.event_camera.ba_filter_window_s=0)
ref=(--set sampling.schedule=whole_frame --set sampling.min_rate_hz=50000 --set sampling.max_rate_hz=50000
     --set sampling.fastest_pixel_quantile=1)
stat() { /usr/bin/python3 -c "import sys, yaml; print(yaml.safe_load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }
for f in "$root"/experiments/scenarios/*.yaml; do
  name="$(basename "$f" .yaml)"
  start=20
  [ "$name" = mars_yard_circle ] && start=6
  win=(--set duration_s="$window" --set start_s="$start")
  row="| $name"
  eq=""
  for sensor in ideal shipped; do
    extra=()
    [ "$sensor" = ideal ] && extra=("${ideal[@]}")
    "$evio" simulate "$f" -o "$out/ref" -q "${quiet[@]}" "${win[@]}" "${extra[@]}" "${ref[@]}"
    "$evio" simulate "$f" -o "$out/whole" -q "${quiet[@]}" "${win[@]}" "${extra[@]}" --set sampling.schedule=whole_frame
    "$evio" simulate "$f" -o "$out/tiles" -q "${quiet[@]}" "${win[@]}" "${extra[@]}" --set sampling.schedule=tiles
    n_ref=$(stat "$out/ref/simulation_stats.yaml" events)
    row+=" | $n_ref"
    for m in whole tiles; do
      n=$(stat "$out/$m/simulation_stats.yaml" events)
      row+=" | $n ($(/usr/bin/python3 -c "print(f'{100.0 * ($n - $n_ref) / max($n_ref, 1):+.2f} %')"))"
    done
    if [ "$sensor" = ideal ]; then
      for m in ref whole tiles; do
        eq+="$(/usr/bin/python3 -c "print(f'{$(stat "$out/$m/simulation_stats.yaml" render_equivalents_per_simulated_s):.0f}')"), "
      done
    fi
    rm -rf "${out:?}/ref" "${out:?}/whole" "${out:?}/tiles"
  done
  echo "$row | ${eq%, } |"
done
echo
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
