#!/usr/bin/env bash
# The module-arrow check must fail on a wrong include, not only pass on the
# repository: a backend source that includes a frontend header, and a frontend
# source that includes the backend, each make scripts/check_dependencies.sh
# exit 1 naming the violation; the same tree without them passes.
set -u
check="$(dirname "$0")/../scripts/check_dependencies.sh"
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
mkdir -p "$tree/estimator/backend/src" "$tree/estimator/frontend/src" "$tree/estimator/contract/include"
echo '#include "evio/estimator/measurements.h"' > "$tree/estimator/backend/src/ok.cpp"
bash "$check" "$tree" > "$tree/out.txt" || { echo "FAIL: a clean tree fails"; cat "$tree/out.txt"; exit 1; }

expect_violation() {  # expect_violation <file> <include> <message>
  echo "#include \"$2\"" > "$tree/$1"
  if bash "$check" "$tree" > "$tree/out.txt"; then echo "FAIL: $1 including $2 passes"; exit 1; fi
  grep -q "$3" "$tree/out.txt" || { echo "FAIL: no '$3' in:"; cat "$tree/out.txt"; exit 1; }
  rm "$tree/$1"
}
expect_violation estimator/backend/src/bad.cpp evio/estimator/frontend/synchronizer.h \
  "the backend includes the frontend"
expect_violation estimator/frontend/src/bad.cpp evio/estimator/backend/backend.h \
  "the frontend includes the backend"
expect_violation estimator/backend/src/bad.cpp evio/estimator/pipeline/pipeline.h \
  "the backend includes the frontend or the pipeline"
echo "the check fails on each wrong include and passes without them"
