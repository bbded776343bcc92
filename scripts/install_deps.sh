#!/usr/bin/env bash
# Installs every Debian 12 package evio needs to build, test, benchmark and plot.
# Idempotent: only packages that are missing are installed. Run as root (or with sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libceres-dev libopencv-dev libembree-dev libtbb-dev
  libopenexr-dev libyaml-cpp-dev libhdf5-dev libcli11-dev libgdal-dev libpng-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  python3 python3-matplotlib python3-numpy python3-yaml python3-pil
  python3-dev pybind11-dev
  dpkg-dev binutils
  librosbag-storage-dev libroscpp-core-dev libsensor-msgs-dev libgeometry-msgs-dev libstd-msgs-dev
  python3-rosbag python3-roslz4 python3-genpy python3-genmsg python3-sensor-msgs python3-geometry-msgs
  python3-std-msgs time
  slurm-wlm munge
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
