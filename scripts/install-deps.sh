#!/usr/bin/env bash
# Installs every Debian 12 package Viscera needs to build, test and benchmark.
# Idempotent: packages already present are skipped by apt.
set -euo pipefail

PKGS=(
  # toolchain
  build-essential cmake ninja-build pkg-config git file
  # core numerics
  libeigen3-dev libsuitesparse-dev
  # case packages (zip + sha256 + json)
  libzip-dev zipcmp zipmerge ziptool libssl-dev nlohmann-json3-dev
  # authoring (studio/bake only; never linked by the player)
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libassimp-dev libopenvdb-dev libtbb-dev libboost-iostreams-dev libblosc-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  # rendering, headless EGL on Mesa (llvmpipe)
  libegl-dev libgl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri mesa-utils libpng-dev
  # Qt6 (studio widgets; the player uses QtGui at most)
  qt6-base-dev libqt6opengl6-dev xvfb xauth
  # synthetic X input for the trainee window's GUI test
  xdotool
  # tests and benchmarks; clang-format for the formatting check (tests/lint)
  libgtest-dev libgmock-dev googletest libbenchmark-dev clang-format
  # packages: cpack (dpkg-deb, fakeroot), checked with lintian
  dpkg-dev fakeroot lintian
  # peer solver for error-time comparisons
  libbullet-dev
  # trainee results database (viscera-results: SQLite, PostgreSQL) and its page check in Chromium
  libsqlite3-dev libpq-dev postgresql chromium
  # the launcher's desktop entry is checked (scripts/package.sh)
  desktop-file-utils
)

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all packages present"
fi
