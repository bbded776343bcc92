#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (address + undefined sanitizers on
# the fuzz targets) and runs each for SECONDS (default 180) from a seed corpus.
# Usage: scripts/fuzz.sh [seconds-per-target]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-180}
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ is required (apt-get install clang)"; exit 1; }
cmake --preset fuzz >/dev/null
names=(events_txt imu_txt tum images_txt config_yaml calib_txt sensors_yaml tracks_txt range_txt imu_state_txt
       track_points_txt event_labels_bin events_h5 scenario_yaml campaign_yaml cli)
# A subset: scripts/fuzz.sh 300 events_h5 cli
[ $# -gt 1 ] && names=("${@:2}")
targets=("${names[@]/#/fuzz_}")
cmake --build --preset fuzz -j "${FUZZ_BUILD_JOBS:-$(nproc)}" --target "${targets[@]}"
corpus=build/fuzz/corpus
for name in "${names[@]}"; do mkdir -p "$corpus/$name"; done
printf '0.000000000 1 2 1\n0.000001000 239 179 0\n' > "$corpus/events_txt/seed"
printf '0.0 0 0 9.81 0 0 0\n0.005 0.1 -0.2 9.8 0.01 0 0\n' > "$corpus/imu_txt/seed"
printf '# t tx ty tz qx qy qz qw\n0.0 0 0 0 0 0 0 1\n0.1 1 2 3 0 0 0.7071068 0.7071068\n' > "$corpus/tum/seed"
printf '0.0 images/frame_00000000.png\n' > "$corpus/images_txt/seed"
printf 'exposure_s: 0.02\ninner:\n  count: 5\noffset_m: [1, 2, 3]\nweights: [1, 2]\n' > "$corpus/config_yaml/seed"
printf '200.0 200.0 120.0 90.0 -0.37 0.16 0.0 0.0 0.0\n' > "$corpus/calib_txt/seed"
printf '0 0.000 10.5 20.25\n0 0.005 10.6 20.3\n1 0.005 50 60\n' > "$corpus/tracks_txt/seed"
printf '0.0 1.5 1\n0.1 0 0\n' > "$corpus/range_txt/seed"
printf '# id px py pz\n0 1.5 -2 0.25\n3 -8.45 0.1 1e-3\n' > "$corpus/track_points_txt/seed"
printf 'EVIOLBL1\003\000\000\000\000\000\000\000\000\001\003' > "$corpus/event_labels_bin/seed"
cp tests/fuzz/seeds/sensors.yaml "$corpus/sensors_yaml/seed" 2>/dev/null || true
cp tests/fuzz/seeds/events_h5/*.h5 "$corpus/events_h5/" 2>/dev/null || true
cp experiments/scenarios/*.yaml "$corpus/scenario_yaml/" 2>/dev/null || true
cp experiments/campaigns/*.yaml "$corpus/campaign_yaml/" 2>/dev/null || true
# Command lines: arguments separated by NUL bytes.
printf 'estimate\x00seq\x00--method\x00klt-vio\x00-o\x00out\x00--set\x00backend.window_size=12' > "$corpus/cli/estimate"
printf 'campaign\x00c.yaml\x00-o\x00r\x00-j\x002\x00--set\x00seeds=[1,2]' > "$corpus/cli/campaign"
printf 'evaluate\x00est\x00gt.txt\x00--align\x00se3\x00--window\x003\x008\x00-o\x00m.json' > "$corpus/cli/evaluate"
printf 'simulate\x00s.yaml\x00-o\x00out\x00--threads\x002\x00--set\x00duration_s=1' > "$corpus/cli/simulate"
printf 'render\x00scene.yaml\x00--camera\x00rig.yaml\x00--pose\x000 0 1 0 0 0 1\x00-o\x00out' > "$corpus/cli/render"
for name in "${names[@]}"; do
  echo "== fuzz_$name for ${seconds}s"
  build/fuzz/tests/fuzz/fuzz_$name -max_total_time="$seconds" -print_final_stats=1 -timeout=10 \
    "$corpus/$name" 2>&1 | grep -E "stat::number_of_executed_units|ERROR|SUMMARY|Done|cov:" | tail -4 || true
done
