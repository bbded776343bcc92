#!/usr/bin/env bash
# Each example of issue 19, reproduced; every check failed on the code before
# the fix (main at 456255d).
#
# usage: issue19_regressions.sh <evio> <source-dir> <work-folder>
set -uo pipefail
evio=$(realpath "$1")
src=$(realpath "$2")
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1
failures=0
fail() {
  echo "REGRESSION: $*" >&2
  failures=$((failures + 1))
}
one_error() { # <label> <expected exit> <command...>: one evio error line, that exit code
  local label=$1 want=$2
  shift 2
  "$@" > out.txt 2> err.txt
  local rc=$?
  [ "$rc" = "$want" ] || fail "$label: exit $rc, expected $want ($(head -c 200 err.txt))"
  grep -q "^evio: error: " err.txt || fail "$label: not an evio error: $(head -c 200 err.txt)"
  grep -q "internal error" err.txt && fail "$label: internal error: $(head -c 200 err.txt)"
}
scenario="$src/experiments/scenarios/poster_rotation.yaml"
"$evio" simulate "$scenario" -o seq --set duration_s=0.3 -q || fail "simulate"
"$evio" simulate "$scenario" -o seq2 --set duration_s=0.3 --set seed=2 -q || fail "simulate"

# 1. An interrupted re-simulation never leaves a mix that `info` accepts.
cp -r seq2 resim
EVIO_FAULT=SIGKILL EVIO_FAULT_AFTER=12 "$evio" simulate "$scenario" -o resim --set duration_s=0.3 -q 2> /dev/null
diff -rq -x simulation_stats.yaml resim seq2 > /dev/null || fail "killed re-simulation changed the previous sequence"
for d in resim.staging.*; do
  [ -e "$d" ] || continue
  "$evio" info "$d" > /dev/null 2>&1 && fail "info accepted the staging folder $d"
done
#    A killed `estimate -o` re-run leaves the old estimate whole (never a mix).
"$evio" estimate seq --method klt-vio --init groundtruth -o est -q || fail "estimate"
cp -r est est_before
EVIO_FAULT=SIGTERM EVIO_FAULT_AFTER=10 "$evio" estimate seq2 --method eklt-vio --init groundtruth -o est -q 2> /dev/null
[ $? = 143 ] || fail "SIGTERM: exit code not 143"
diff -rq est est_before > /dev/null || fail "killed estimate re-run changed the previous estimate"

# 2. A full disk (file-size limit) during estimate: no complete-looking trajectory.txt.
(ulimit -f 1; "$evio" estimate seq --method eklt-vio --init groundtruth -o est_full -q) 2> err.txt
rc=$?
[ "$rc" = 1 ] || fail "estimate on a full disk: exit $rc"
[ -e est_full/trajectory.txt ] && fail "estimate on a full disk left trajectory.txt"
grep -q "^evio: error: .*est_full" err.txt || fail "estimate on a full disk: the error does not name the path: $(cat err.txt)"

# 3. SIGINT/SIGTERM leave no *.tmp.PID.N and no staging folder.
for s in SIGINT SIGTERM; do
  EVIO_FAULT=$s EVIO_FAULT_AFTER=5 "$evio" simulate "$scenario" -o sig_$s --set duration_s=0.3 -q 2> /dev/null
  left=$(find . -maxdepth 3 \( -name "sig_$s*.tmp.*" -o -name "sig_$s.staging.*" -o -path "./sig_$s*" \))
  [ -z "$left" ] || fail "$s left: $left"
done
#    A failed rename in the atomic writer leaves no temporary file (target is a folder).
mkdir -p ren/m.json
"$evio" evaluate est seq -o ren/m.json -q 2> err.txt && fail "evaluate onto a folder succeeded"
[ -z "$(find ren -name '*.tmp.*' -o -name '*.staging.*')" ] || fail "failed rename left temporaries"

# 4. eklt-vio on an empty events.txt: not `ok` with zero poses and exit 0.
cp -r seq empty
rm -f empty/events.h5
grep '^#' seq/events.txt > empty/events.txt || true
"$evio" estimate empty --method eklt-vio --init groundtruth -o est_empty -q 2> err.txt
rc=$?
if [ "$rc" = 0 ]; then
  fail "eklt-vio on an empty events.txt exited 0 ($(grep status est_empty/status.yaml))"
fi

# 5. A timestamp near 9.22e9 s is an error, not a negative time.
cp -r seq big
sed -i '3s/^[^ ]*/9223372036.9/' big/groundtruth.txt
one_error "timestamp 9.22e9 s" 1 "$evio" info big
grep -q "groundtruth.txt:3" err.txt || fail "timestamp error does not name groundtruth.txt:3: $(cat err.txt)"

# 6. Line length is bounded: a 64 MiB line is an error naming file and line.
cp -r seq long
head -c 67108864 /dev/zero | tr '\0' '7' > long/imu.txt
one_error "64 MiB line" 1 "$evio" info long
grep -q "imu.txt:1: line longer than" err.txt || fail "long line: $(cat err.txt)"

# 7. --config pointing at a directory is an error.
mkdir -p cfgdir
one_error "--config a folder" 1 "$evio" estimate seq --method klt-vio --config cfgdir -o est_cfg -q
[ -e est_cfg ] && fail "--config a folder: output written"

# 8. A directory where a file belongs, a symlink loop, an output under a file: one evio error.
cp -r seq dirfile
rm dirfile/calib.txt dirfile/sensors.yaml
mkdir dirfile/sensors.yaml
one_error "sensors.yaml a folder" 1 "$evio" estimate dirfile --method klt-vio --init groundtruth -o est_dir -q
cp -r seq loop
rm loop/sensors.yaml
ln -s sensors.yaml loop/sensors.yaml
one_error "symlink loop" 1 "$evio" estimate loop --method klt-vio --init groundtruth -o est_loop -q
touch afile
one_error "output under a file" 1 "$evio" estimate seq --method klt-vio --init groundtruth -o afile/est -q
grep -q "afile" err.txt || fail "output under a file: the error does not name afile"
one_error "simulate under a file" 1 "$evio" simulate "$scenario" -o afile/seq --set duration_s=0.3 -q

# 9. sampling.min_rate_hz has an upper bound.
one_error "min_rate_hz 1e12" 1 timeout 60 "$evio" simulate "$scenario" -o fast --set duration_s=0.2 \
  --set sampling.min_rate_hz=1e12 --set sampling.max_rate_hz=1e12 -q
grep -q "min_rate_hz" err.txt || fail "min_rate_hz: $(cat err.txt)"

if [ "$failures" -gt 0 ]; then
  echo "issue19_regressions: $failures FAILURES" >&2
  exit 1
fi
echo "issue19_regressions: PASSED"
