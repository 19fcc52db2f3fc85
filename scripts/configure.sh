#!/usr/bin/env bash
# Shared by demo.sh and test.sh: install what is missing, configure and build the given targets.
# Usage: scripts/configure.sh [target...]   (no target: everything)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD_DIR=${VISCERA_BUILD_DIR:-build}
JOBS=${VISCERA_JOBS:-$(nproc)}
if [[ ! -f "$BUILD_DIR/build.ninja" ]]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
if (($#)); then
  cmake --build "$BUILD_DIR" -j"$JOBS" --target "$@"
else
  cmake --build "$BUILD_DIR" -j"$JOBS"
fi
