#!/usr/bin/env bash
# Simulation speed of every shipped scenario (README "Simulation (issue 5)"),
# with both render schedules one after the other in the same run so that
# their ratio is comparable on a shared machine: simulates a window of each
# scenario (default 2 s from t = 20 s, or the whole scenario when it is
# shorter) with sampling.schedule=whole_frame and =tiles, and prints one
# Markdown row per scenario and schedule from the run's
# simulation_stats.yaml, with the machine and its load.
#   scripts/simulation_speed.sh [build-dir] [window-s] [schedules]
#   (default: build/release 2 "whole_frame tiles")
# mars_yard_circle (10 s) always runs whole: it is the target scenario.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/release}"
window="${2:-2}"
schedules="${3:-whole_frame tiles}"
evio="$build/bin/evio"
[ -x "$evio" ] || { echo "simulation_speed: $evio not found (build the 'evio' target first)" >&2; exit 1; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; load before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| scenario | window | resolution | schedule | sim s / wall s | sim s / CPU s | events / sim s | renders / sim s (whole-image equivalents) | event stage, M pixel updates / wall s, / CPU s |"
echo "|---|---|---|---|---:|---:|---:|---:|---|"
for f in "$root"/experiments/scenarios/*.yaml; do
  name="$(basename "$f" .yaml)"
  args=(--set output.write_events_txt=false)
  span="whole"
  if [ "$name" != mars_yard_circle ]; then
    args+=(--set duration_s="$window" --set start_s=20)
    span="${window} s from 20 s"
  fi
  for schedule in $schedules; do
    "$evio" simulate "$f" -o "$out/$name" -q "${args[@]}" --set sampling.schedule="$schedule"
    /usr/bin/python3 - "$out/$name/simulation_stats.yaml" "$name" "$span" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
r = s["resolution"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {r[0]}x{r[1]} | {s['schedule']} | {s['simulated_s_per_wall_s']:.3f} | "
      f"{s['simulated_s_per_cpu_s']:.3f} | {s['events_per_simulated_s']/1e3:.0f} k | "
      f"{s['render_equivalents_per_simulated_s']:.0f} | {s['event_stage_pixel_updates_per_s']/1e6:.0f}, "
      f"{s['event_stage_pixel_updates_per_cpu_s']/1e6:.0f} |")
PY
    rm -rf "${out:?}/$name"
  done
done
echo
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
