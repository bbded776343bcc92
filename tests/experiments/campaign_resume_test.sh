#!/usr/bin/env bash
# A killed-and-resumed campaign gives the same results as an uninterrupted one.
#
# Runs a campaign once without interruption, and once killed with SIGKILL
# after a few jobs have finished (with jobs in flight), then resumed; the
# summaries (summary.csv) and every job's per-pose errors must be
# byte-identical, no staging folder may be left, and the resumed run must
# have skipped the jobs finished before the kill.
#
# usage: campaign_resume_test.sh <evio> <campaign.yaml> <work-folder> [--set key=value]...
set -euo pipefail
evio=$1
campaign=$2
work=$3
shift 3
rm -rf "$work"
mkdir -p "$work"

"$evio" campaign "$campaign" -o "$work/reference" -j 2 -q "$@" || [ $? -eq 3 ]  # 3: some jobs failed (as planned)
total=$(($(wc -l < "$work/reference/summary.csv") - 1))

"$evio" campaign "$campaign" -o "$work/resumed" -j 2 -q "$@" &
pid=$!
for _ in $(seq 1 1200); do
  n=$({ find "$work/resumed/jobs" -mindepth 1 -maxdepth 1 2> /dev/null || true; } | wc -l)
  [ "$n" -ge 4 ] && break
  sleep 0.02
done
kill -9 "$pid"
wait "$pid" 2> /dev/null || true
before=$(find "$work/resumed/jobs" -mindepth 1 -maxdepth 1 | wc -l)
in_flight=$(find "$work/resumed/staging" -mindepth 1 -maxdepth 1 | wc -l)
echo "campaign_resume_test: killed after $before of $total jobs, $in_flight in flight"
if [ "$before" -ge "$total" ]; then
  echo "campaign_resume_test: the campaign finished before it was killed; nothing tested" >&2
  exit 1
fi

out=$("$evio" campaign "$campaign" -o "$work/resumed" -j 2 "$@" || [ $? -eq 3 ])
echo "$out" | tail -n 1
echo "$out" | grep -q "$before done already" || { echo "resumed run did not skip the $before finished jobs" >&2; exit 1; }

cmp "$work/reference/summary.csv" "$work/resumed/summary.csv"
for d in "$work/reference/jobs"/*/; do
  id=$(basename "$d")
  cmp "$d/metrics_poses.csv" "$work/resumed/jobs/$id/metrics_poses.csv" 2> /dev/null ||
    [ ! -f "$d/metrics_poses.csv" ] || { echo "jobs/$id differs" >&2; exit 1; }
done
if [ -n "$(ls -A "$work/resumed/staging")" ]; then
  echo "staging folders left behind: $(ls "$work/resumed/staging")" >&2
  exit 1
fi
echo "campaign_resume_test: PASSED ($total jobs; killed after $before, resumed, identical)"
