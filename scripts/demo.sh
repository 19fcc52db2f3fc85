#!/usr/bin/env bash
# Main job on a built-in default case: install, build, export the sample project to a case
# package, verify it and run it headless in the player; prints a summary and the report path.
# Usage: scripts/demo.sh [project-name] [frames]     (default: tissue-slab 300)
set -euo pipefail
cd "$(dirname "$0")/.."
PROJECT=${1:-tissue-slab}
FRAMES=${2:-300}
BUILD_DIR=${VISCERA_BUILD_DIR:-build}
bash scripts/configure.sh viscera-studio viscera-player viscera_sample_key viscera_rectum_anatomy
mkdir -p out
# Signed with the build's sample publisher key (a test key); the player trusts its public half.
key="$BUILD_DIR/keys/viscera-samples.pem"
"$BUILD_DIR/studio/cli/viscera-studio" export "projects/$PROJECT" -o "out/$PROJECT.vcase" \
  --sign-key "$key" --signer "Viscera samples (test key)"
"$BUILD_DIR/player/viscera-player" verify "out/$PROJECT.vcase" --trust "${key%.pem}.pub.pem"
"$BUILD_DIR/player/viscera-player" run "out/$PROJECT.vcase" --trust "${key%.pem}.pub.pem" --headless --frames "$FRAMES" \
  --report "out/$PROJECT-report.json"
