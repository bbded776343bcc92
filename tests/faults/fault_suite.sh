#!/usr/bin/env bash
# The fault-injection suite (ctest label `faults`; issue 19).
#
# Kills `evio simulate`, `estimate`, `evaluate` and `campaign` with SIGINT,
# SIGTERM and SIGKILL at points chosen by a seeded schedule (the N-th write,
# commit or rename: EVIO_FAULT_AFTER=N with EVIO_FAULT=SIGINT|SIGTERM|SIGKILL,
# or EIO for a failed write; honoured by test builds, core/io/staged_folder.h),
# runs them under file-size limits (ulimit -f: EFBIG, like a full disk) and on
# damaged inputs, and after every fault re-reads the target: it must be the
# previous complete output, the new complete output, or absent, never a mix;
# SIGINT/SIGTERM must leave no staging or temporary files, and the next run
# into the same target must succeed and remove what a SIGKILL left.
#
# usage: fault_suite.sh <evio> <source-dir> <work-folder> [seed] [points-per-signal]
set -uo pipefail
evio=$(realpath "$1")
src=$(realpath "$2")
work=$3
seed=${4:-19}
per=${5:-5}
RANDOM=$seed
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1
scenario="$src/experiments/scenarios/poster_rotation.yaml"
sim_set=(--set duration_s=0.3)
failures=0
declare -A injected outcome_prev outcome_new outcome_none

fail() {
  echo "FAULT SUITE FAILURE: $*" >&2
  failures=$((failures + 1))
}

# Same content apart from wall-clock fields?
same_sequence() { diff -rq -x simulation_stats.yaml "$1" "$2" > /dev/null 2>&1; }
same_estimate() {
  for f in trajectory.txt trajectory_covariance.txt imu_state.txt status.yaml config.yaml; do
    cmp -s "$1/$f" "$2/$f" || return 1
  done
  for f in timing.txt summary.yaml; do [ -f "$1/$f" ] || return 1; done
}
same_metrics() { # <stem-a> <stem-b>: metrics.json and its companions
  cmp -s "$1.json" "$2.json" && cmp -s "$1_poses.csv" "$2_poses.csv" && cmp -s "$1_rtf.csv" "$2_rtf.csv"
}
leftovers() { # staging or temporary names beside/inside $1
  find "$(dirname "$1")" -maxdepth 3 \( -name '*.staging.*' -o -name '*.tmp.*' -o -name '*.old.*' \) 2> /dev/null
}

# classify <kind> <target> <previous> <new>: prev | new | none, or fail
classify() {
  local kind=$1 target=$2 prev=$3 new=$4
  case $kind in
    sequence)
      if [ ! -e "$target" ]; then echo none
      elif same_sequence "$target" "$prev"; then echo prev
      elif same_sequence "$target" "$new"; then echo new
      else echo mixed; fi ;;
    estimate)
      if [ ! -e "$target" ]; then echo none
      elif same_estimate "$target" "$prev"; then echo prev
      elif same_estimate "$target" "$new"; then echo new
      else echo mixed; fi ;;
    metrics)
      if [ ! -e "$target.json" ]; then echo none
      elif same_metrics "$target" "$prev"; then echo prev
      elif same_metrics "$target" "$new"; then echo new
      else echo mixed; fi ;;
  esac
}

# The reference outputs: previous (another seed / method) and new.
"$evio" simulate "$scenario" -o ref_prev_seq "${sim_set[@]}" --set seed=2 -q || fail "reference simulate"
EVIO_FAULT_COUNT_FILE=$work/count.simulate "$evio" simulate "$scenario" -o ref_new_seq "${sim_set[@]}" -q ||
  fail "reference simulate"
est=(estimate ref_new_seq --init groundtruth -q)
"$evio" "${est[@]}" --method klt-vio -o ref_prev_est || fail "reference estimate"
EVIO_FAULT_COUNT_FILE=$work/count.estimate "$evio" "${est[@]}" --method eklt-vio -o ref_new_est ||
  fail "reference estimate"
"$evio" evaluate ref_prev_est ref_new_seq -o ref_prev_m.json -q || fail "reference evaluate"
EVIO_FAULT_COUNT_FILE=$work/count.evaluate "$evio" evaluate ref_new_est ref_new_seq -o ref_new_m.json -q ||
  fail "reference evaluate"

# run_cmd <command> <target>: the faulted command line
run_cmd() {
  case $1 in
    simulate) "$evio" simulate "$scenario" -o "$2" "${sim_set[@]}" -q ;;
    estimate) "$evio" "${est[@]}" --method eklt-vio -o "$2" ;;
    evaluate) "$evio" evaluate ref_new_est ref_new_seq -o "$2.json" -q ;;
  esac
}
prepare_prev() { # <command> <target>
  rm -rf "$2" "$2".json "$2"_poses.csv "$2"_rtf.csv
  case $1 in
    simulate) cp -r ref_prev_seq "$2" ;;
    estimate) cp -r ref_prev_est "$2" ;;
    evaluate) cp ref_prev_m.json "$2.json"; cp ref_prev_m_poses.csv "$2_poses.csv"; cp ref_prev_m_rtf.csv "$2_rtf.csv" ;;
  esac
}
kind_of() { case $1 in simulate) echo sequence ;; estimate) echo estimate ;; evaluate) echo metrics ;; esac; }
ref_of() { case $1 in simulate) echo "ref_$2_seq" ;; estimate) echo "ref_$2_est" ;; evaluate) echo "ref_$2_m" ;; esac; }

record() { # <command> <outcome>
  injected[$1]=$((${injected[$1]:-0} + 1))
  case $2 in
    prev) outcome_prev[$1]=$((${outcome_prev[$1]:-0} + 1)) ;;
    new) outcome_new[$1]=$((${outcome_new[$1]:-0} + 1)) ;;
    none) outcome_none[$1]=$((${outcome_none[$1]:-0} + 1)) ;;
  esac
}

check_fault() { # <command> <label> <rc> <target> <with-previous: 0|1>
  local cmd=$1 label=$2 rc=$3 target=$4 had_prev=$5 o
  o=$(classify "$(kind_of "$cmd")" "$target" "$(ref_of "$cmd" prev)" "$(ref_of "$cmd" new)")
  [ "$o" = mixed ] && fail "$cmd $label: the target is neither the previous nor the new output"
  [ "$o" = prev ] && [ "$had_prev" = 0 ] && fail "$cmd $label: an output appeared from nowhere"
  [ "$rc" = 0 ] && [ "$o" != new ] && fail "$cmd $label: exit 0 without the new output"
  [ "$rc" != 0 ] && [ "$o" = new ] && [ "$rc" != 137 ] && [ "$rc" != 130 ] && [ "$rc" != 143 ] &&
    fail "$cmd $label: exit $rc but the new output was published"
  case $label in
    SIGINT* | SIGTERM* | EIO* | fsize*)
      if [ "$rc" != 0 ] && [ -n "$(leftovers "$target")" ]; then
        fail "$cmd $label: left $(leftovers "$target" | tr '\n' ' ')"
      fi ;;
  esac
  record "$cmd" "$o"
}

# ---- signals and failed writes at scheduled points ------------------------------
for cmd in simulate estimate evaluate; do
  total=$(cat "count.$cmd" 2> /dev/null || echo 0)
  [ "$total" -gt 0 ] || { fail "$cmd: no fault points counted"; continue; }
  for action in SIGINT SIGTERM SIGKILL EIO; do
    for _ in $(seq 1 "$per"); do
      n=$((RANDOM % (total + 2) + 1))  # 1 .. total+2: the last ones complete
      for had_prev in 0 1; do
        target="t_$cmd"
        rm -rf "$target" "$target".json "$target"_poses.csv "$target"_rtf.csv "$target".staging.* "$target".json.staging.*
        [ "$had_prev" = 1 ] && prepare_prev "$cmd" "$target"
        EVIO_FAULT=$action EVIO_FAULT_AFTER=$n run_cmd "$cmd" "$target" > /dev/null 2> err.txt
        rc=$?
        check_fault "$cmd" "$action@$n" "$rc" "$target" "$had_prev"
        if [ "$action" = EIO ] && [ "$rc" != 0 ]; then
          [ "$rc" = 1 ] && grep -q "^evio: error: .*injected fault" err.txt ||
            fail "$cmd EIO@$n: exit $rc, not one evio error: $(head -c 300 err.txt)"
        fi
        # The next run into the same target succeeds and clears what was left.
        run_cmd "$cmd" "$target" > /dev/null 2>&1 || fail "$cmd after $action@$n: the next run failed"
        [ "$(classify "$(kind_of "$cmd")" "$target" "$(ref_of "$cmd" prev)" "$(ref_of "$cmd" new)")" = new ] ||
          fail "$cmd after $action@$n: the next run did not publish the new output"
        [ -z "$(leftovers "$target")" ] || fail "$cmd after $action@$n: left $(leftovers "$target" | tr '\n' ' ')"
      done
    done
  done
done

# ---- write failures: a file-size limit (EFBIG, like a full disk) -------------------------
for cmd in simulate estimate evaluate; do
  for kb in 1 4 16 64; do
    target="t_$cmd"
    prepare_prev "$cmd" "$target"
    (ulimit -f "$kb"; run_cmd "$cmd" "$target") > /dev/null 2> err.txt
    rc=$?
    check_fault "$cmd" "fsize${kb}k" "$rc" "$target" 1
    if [ "$rc" != 0 ]; then
      [ "$rc" = 1 ] && [ "$(wc -l < err.txt)" -le 2 ] && grep -q "^evio: error: " err.txt ||
        fail "$cmd fsize ${kb}k: exit $rc, not one evio error: $(head -c 300 err.txt)"
    fi
  done
done

# ---- read failures: damaged inputs end in one evio error and no output --------------------
damage() { # <label> <setup command...>: copy the sequence, damage it, estimate and info must fail cleanly
  local label=$1
  shift
  rm -rf dmg dmg_out
  cp -r ref_new_seq dmg
  "$@"
  for c in info estimate; do
    if [ $c = info ]; then "$evio" info dmg > /dev/null 2> err.txt; else "$evio" "${est[@]/ref_new_seq/dmg}" --method eklt-vio -o dmg_out > /dev/null 2> err.txt; fi
    rc=$?
    injected[read]=$((${injected[read]:-0} + 1))
    if [ "$rc" = 1 ] && grep -q "^evio: error: " err.txt && [ ! -e dmg_out ] && [ -z "$(leftovers dmg_out)" ]; then
      outcome_none[read]=$((${outcome_none[read]:-0} + 1))
    elif [ $c = info ] && [ "$rc" = 0 ] && [ "$label" = "images.txt folder" ]; then
      fail "read $label ($c): accepted"
    else
      fail "read $label ($c): exit $rc, $(head -c 200 err.txt)"
    fi
  done
}
damage "events.txt truncated mid-line" bash -c 'rm -f dmg/events.h5; head -c 5000 ref_new_seq/events.txt > dmg/events.txt'
damage "events.h5 truncated" bash -c 'head -c 3000 ref_new_seq/events.h5 > dmg/events.h5'
damage "imu.txt is a folder" bash -c 'rm dmg/imu.txt; mkdir dmg/imu.txt'
damage "imu.txt line of 2 MiB" bash -c 'head -c 2097152 /dev/zero | tr "\0" "1" >> dmg/imu.txt'
damage "groundtruth time overflows" bash -c 'sed -i "3s/^[^ ]*/9223372037.0/" dmg/groundtruth.txt'
damage "sensors.yaml symlink loop" bash -c 'rm dmg/sensors.yaml; ln -s sensors.yaml dmg/sensors.yaml'
# A crafted events.h5 (found by fuzz_events_h5) on which libhdf5 itself divides
# by zero in H5Dopen2 (a chunk dimension of 0): one evio error, not SIGFPE.
damage "events.h5 that crashes libhdf5" bash -c "rm -f dmg/events.txt; cp '$src/tests/faults/data/events_h5_chunk_dim_zero.h5' dmg/events.h5"

# ---- campaign: the campaign process killed inside its children, then resumed ------------------
campaign_file="$src/experiments/campaigns/smoke.yaml"
campaign_set=(--set 'seeds=[1]')
"$evio" campaign "$campaign_file" -o camp_ref -j 2 -q "${campaign_set[@]}" > /dev/null 2>&1
rc=$?
[ "$rc" = 0 ] || [ "$rc" = 3 ] || fail "campaign reference: exit $rc"
# The kill points: the campaign is killed while its k-th child of one kind
# runs (a simulate, estimate or evaluate step, the kinds in turn; k drawn from
# the seeded schedule), so every kill lands inside a child's work. Smoke with
# one seed runs 2 simulate, 12 estimate and 12 evaluate children.
declare -A kill_in
child_kind() { # <pid>: simulate | estimate | evaluate | other; "" when it is gone
  local argv=()
  mapfile -d '' -t argv < "/proc/$1/cmdline" 2> /dev/null || return 0
  [ "${#argv[@]}" -gt 0 ] || return 0
  case "${argv[0]##*/} ${argv[1]:-}" in
    "evio trajectory" | "evio simulate") echo simulate ;;
    "evio_fake_estimator "* | "evio estimate") echo estimate ;;
    "evio evaluate") echo evaluate ;;
    *) echo other ;;
  esac
}
alive() { # <pid>: running (not gone, not a zombie), read with builtins only
  local st
  read -r st < "/proc/$1/stat" 2> /dev/null || return 1
  st=${st##*) }
  [ "${st:0:1}" != Z ]
}
kinds=(simulate estimate evaluate)
point=0
for action in INT TERM KILL; do
  for _ in $(seq 1 "$per"); do
    want=${kinds[$((point % 3))]}
    point=$((point + 1))
    if [ "$want" = simulate ]; then k=$((RANDOM % 2 + 1)); else k=$((RANDOM % 6 + 1)); fi
    rm -rf camp
    "$evio" campaign "$campaign_file" -o camp -j 2 -q "${campaign_set[@]}" > /dev/null 2>&1 &
    pid=$!
    declare -A kind_of_child=()
    declare -A count=()
    kind=none
    # Busy polling with builtins only (children of every thread of the
    # campaign, from /proc): a fake estimate lives for a few milliseconds.
    while alive "$pid"; do
      hit=""
      live=()
      for t in /proc/"$pid"/task/*/children; do
        read -r -a tk < "$t" 2> /dev/null || true
        live+=("${tk[@]}")
      done
      for c in "${live[@]}"; do
        if [ -z "${kind_of_child[$c]:-}" ]; then
          kc=$(child_kind "$c")
          [ -n "$kc" ] && [ "$kc" != other ] || continue  # gone, or not yet exec'd
          kind_of_child[$c]=$kc
          count[$kc]=$((${count[$kc]:-0} + 1))
        fi
        [ "${kind_of_child[$c]}" = "$want" ] && [ "${count[$want]:-0}" -ge "$k" ] && hit=$c
      done
      if [ -n "$hit" ]; then
        kind=$want
        kill -s "$action" "$pid" 2> /dev/null
        break
      fi
    done
    unset kind_of_child count
    wait "$pid" 2> /dev/null
    rc=$?
    injected[campaign]=$((${injected[campaign]:-0} + 1))
    kill_in[$kind]=$((${kill_in[$kind]:-0} + 1))
    # Every published job is complete; SIGINT/SIGTERM left no staging, in the
    # job staging area or in the sequence cache (a simulate child's folder).
    for j in camp/jobs/*/; do
      [ -d "$j" ] || continue
      [ -f "$j/metrics.json" ] && [ -f "$j/job.yaml" ] || fail "campaign $action@$want$k: incomplete $(basename "$j")"
    done
    if [ "$action" != KILL ] && [ "$rc" != 0 ] && [ "$rc" != 3 ]; then
      [ -z "$(ls -A camp/staging 2> /dev/null)" ] || fail "campaign $action@$want$k: staging left: $(ls camp/staging)"
      [ -z "$(leftovers camp/sequences/x)" ] ||
        fail "campaign $action@$want$k: left in the sequence cache: $(leftovers camp/sequences/x | tr '\n' ' ')"
      [ "$rc" = $((128 + $(kill -l "$action"))) ] || fail "campaign $action: exit $rc"
    fi
    if [ "$rc" = 0 ] || [ "$rc" = 3 ]; then outcome_new[campaign]=$((${outcome_new[campaign]:-0} + 1))
    else outcome_none[campaign]=$((${outcome_none[campaign]:-0} + 1)); fi
    "$evio" campaign "$campaign_file" -o camp -j 2 -q "${campaign_set[@]}" > /dev/null 2>&1
    rc=$?
    { [ "$rc" = 0 ] || [ "$rc" = 3 ]; } || fail "campaign resume after $action: exit $rc"
    cmp -s camp_ref/summary.csv camp/summary.csv || fail "campaign resume after $action@$want$k: summary differs"
    [ -z "$(ls -A camp/staging)" ] || fail "campaign resume after $action: staging left"
    [ -z "$(leftovers camp/sequences/x)" ] || fail "campaign resume after $action: left $(leftovers camp/sequences/x)"
  done
done
[ "${kill_in[none]:-0}" = 0 ] || fail "campaign: ${kill_in[none]} kills found no child running (the schedule missed)"
for kd in simulate estimate evaluate; do
  [ "$per" -lt 3 ] || [ "${kill_in[$kd]:-0}" -gt 0 ] || fail "campaign: no kill landed in a $kd child"
done

echo "fault suite (seed $seed): command: injected faults -> previous output / new output / nothing"
for c in simulate estimate evaluate campaign read; do
  echo "  $c: ${injected[$c]:-0} -> ${outcome_prev[$c]:-0} / ${outcome_new[$c]:-0} / ${outcome_none[$c]:-0}"
done
echo "  campaign kills inside a child: simulate ${kill_in[simulate]:-0}, estimate ${kill_in[estimate]:-0}," \
  "evaluate ${kill_in[evaluate]:-0}, other ${kill_in[other]:-0}, none ${kill_in[none]:-0}"
if [ "$failures" -gt 0 ]; then
  echo "fault suite: $failures FAILURES" >&2
  exit 1
fi
echo "fault suite: PASSED (no output lost, mixed or half-written)"
