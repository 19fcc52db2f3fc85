#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer [issue 19 item 3]:
# configures build-asan/ with -DVISCERA_SANITIZE=address,undefined (every report aborts the
# process, so a finding fails its test; leaks are reported at exit), builds it and runs the
# steps of scripts/test.sh on it: the tests without GL, the GL tests (headless EGL, Mesa
# llvmpipe) and the GUI tests (Xvfb). Lint and the packages are left to test.sh (nothing there is
# compiled). Leaks inside Mesa, fontconfig and the X/Qt platform libraries (allocated once per
# process by them, not by us) are suppressed by library in scripts/lsan.supp; nothing of ours is.
#
#   scripts/sanitize.sh [build-dir=build-asan]       (about 1 h on 2 cores: a third is the build)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build-asan}"
JOBS=${VISCERA_JOBS:-$(nproc)}
bash scripts/install-deps.sh
if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVISCERA_SANITIZE=address,undefined \
    -DVISCERA_BUILD_BENCH=OFF
fi
cmake --build "$build" -j"$JOBS"
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0:${LSAN_OPTIONS:-}"
status=0
echo "== sanitized tests (no GL) =="
ctest --test-dir "$build" --output-on-failure -j"$JOBS" -LE '^(gl|lint|gui)$' || status=1
echo "== sanitized GL tests (headless EGL) =="
LIBGL_ALWAYS_SOFTWARE=1 ctest --test-dir "$build" --output-on-failure -j"$JOBS" -L '^gl$' || status=1
echo "== sanitized GUI tests (Xvfb + Mesa) =="
env -u QT_QPA_PLATFORM LIBGL_ALWAYS_SOFTWARE=1 xvfb-run -a -s "-screen 0 1920x1200x24 -nolisten tcp" \
  ctest --test-dir "$build" --output-on-failure -j1 -L '^gui$' || status=1
exit $status
