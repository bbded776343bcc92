#!/usr/bin/env bash
# Installs evio into a scratch prefix, and unpacks its Debian package, and
# runs each from an unrelated folder: the binary must find its presets,
# scenarios, estimator configurations and plot scripts relative to itself,
# and nothing of the source tree may be compiled into it.
#   install_test.sh <build folder> <source folder>
set -euo pipefail
build=$(realpath "$1")
source=$(realpath "$2")
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# The Python package installed under the prefix $1 runs the binary beside it, and reads a sequence.
check_python() {
  local prefix=$1 found
  found=$(cd "$scratch" && PYTHONPATH=$prefix/lib/python3/dist-packages /usr/bin/python3 -c 'import evio; print(evio.binary())') \
    || fail "import evio from $prefix"
  [[ $(realpath "$found") == $(realpath "$prefix/bin/evio") ]] || fail "the package under $prefix runs $found"
  # A PGM frame: decoded by the media module installed beside the package.
  mkdir -p "$scratch/pgm/images"
  printf 'P5\n3 2\n255\n\001\002\003\004\005\006' > "$scratch/pgm/images/f.pgm"
  echo "0.5 images/f.pgm" > "$scratch/pgm/images.txt"
  found=$(cd "$scratch" && env -u EVIO_MEDIA_MODULE PYTHONPATH=$prefix/lib/python3/dist-packages /usr/bin/python3 -c \
    'import evio; print([p.tolist() for t, p in evio.iter_frames("pgm")])') || fail "a PGM frame through the package under $prefix"
  [[ $found == "[[[1, 2, 3], [4, 5, 6]]]" ]] || fail "the PGM frame read as $found"
}

# Runs the installed binary $1 in an empty folder on a short simulated sequence.
exercise() {
  local evio=$1 work
  work=$(mktemp -d "$scratch/work.XXXX")
  cd "$work"
  "$evio" --version >/dev/null || fail "$evio --version"
  # A scenario named by its data-folder path; it pulls scene, trajectory and sensor presets.
  "$evio" simulate experiments/scenarios/poster_6dof.yaml --set duration_s=1 output.write_events_txt=false -o seq -q \
    || fail "simulate from $evio"
  "$evio" info seq >/dev/null || fail "info"
  # A video: FFmpeg through the media module installed beside the binary.
  env -u EVIO_MEDIA_MODULE "$evio" video seq -o seq.mp4 --fps 10 -q || fail "video from $evio (the media module)"
  [[ -s seq.mp4 ]] || fail "video wrote no file"
  # An estimator configuration named by its data-folder path.
  "$evio" estimate seq --method klt-vio --config estimator/config/sim.yaml --init groundtruth -o est -q \
    || fail "estimate with estimator/config/sim.yaml"
  grep -qx 'status: ok' est/status.yaml || fail "estimate did not end ok: $(cat est/status.yaml)"
  # A plot script from the data folder (only where matplotlib is installed).
  if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
    "$evio" stats seq --plot stats.png -q >/dev/null || fail "stats --plot"
    [[ -s stats.png ]] || fail "stats --plot wrote no PNG"
  fi
  cd "$scratch"
}

# 1. cmake --install into a prefix.
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
evio=$scratch/prefix/bin/evio
[[ -x $evio ]] || fail "no installed binary at $evio"
[[ -f $scratch/prefix/share/evio/experiments/campaigns/main.yaml ]] || fail "campaigns not installed"
if strings "$evio" | grep -qF "$source"; then fail "the installed binary contains the source path $source"; fi
exercise "$evio"
check_python "$scratch/prefix"

# 2. Without its data folder the binary says which folder is missing (exit 1).
mv "$scratch/prefix/share/evio" "$scratch/moved"
set +e
msg=$(cd "$scratch" && "$evio" simulate experiments/scenarios/poster_6dof.yaml -o x -q 2>&1); code=$?
set -e
[[ $code -eq 1 ]] || fail "missing data folder: exit $code, expected 1"
grep -qF "$scratch/prefix/share/evio" <<<"$msg" || fail "missing data folder not named: $msg"
# ... and EVIO_DATA_DIR points it at a moved one.
EVIO_DATA_DIR=$scratch/moved exercise "$evio"

# 3. The Debian package, unpacked (no root needed): /usr/bin/evio with /usr/share/evio.
cpack --config "$build/CPackConfig.cmake" -B "$scratch/pkg" >/dev/null || fail "cpack"
deb=$(ls "$scratch"/pkg/*.deb)
dpkg-deb -f "$deb" Depends | grep -q libembree || fail "package depends on no libembree: $(dpkg-deb -f "$deb" Depends)"
dpkg-deb -x "$deb" "$scratch/root"
exercise "$scratch/root/usr/bin/evio"
check_python "$scratch/root/usr"
echo "install test passed: prefix, moved data folder, Debian package ($(basename "$deb"))"
