#!/usr/bin/env bash
# Installs what is missing, builds everything and runs the whole test suite with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${VISCERA_BUILD_DIR:-build}
bash scripts/configure.sh
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"${VISCERA_JOBS:-$(nproc)}"
