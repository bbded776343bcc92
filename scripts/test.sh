#!/usr/bin/env bash
# The test command: installs what is missing, configures (warnings as errors),
# builds everything and runs the whole ctest suite, slow and slurm labels included.
# Usage: scripts/test.sh [extra ctest arguments]
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install_deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake --preset ci
cmake --build --preset ci -j "$jobs"
ctest --preset ci -j "$jobs" "$@"
