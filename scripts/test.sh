#!/usr/bin/env bash
# Installs what is missing, builds everything and runs the whole test suite with CTest, in three
# steps: lint (label "lint": clang-format --dry-run -Werror over the sources, the namespace rule),
# everything that needs no OpenGL context, then the GL tests (label "gl": headless EGL, Mesa
# llvmpipe without a GPU). The GL step fails when no context can be created
# (render_gl_context_available), so skipped GL tests cannot hide a machine without EGL.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${VISCERA_BUILD_DIR:-build}
JOBS=${VISCERA_JOBS:-$(nproc)}
bash scripts/configure.sh
status=0
echo "== lint (clang-format, namespaces) =="
ctest --test-dir "$BUILD_DIR" --output-on-failure -L '^lint$' || status=1
echo "== tests (no GL) =="
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" -LE '^(gl|lint)$' || status=1
echo "== GL tests (headless EGL) =="
LIBGL_ALWAYS_SOFTWARE=${LIBGL_ALWAYS_SOFTWARE:-1} \
  ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$JOBS" -L '^gl$' || status=1
exit $status
