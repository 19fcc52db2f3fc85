#!/usr/bin/env bash
# Fuzzes every reader of outside input with libFuzzer [issue 19, issue 58 item 5]: builds the
# harnesses of fuzz/ with clang-14 (-fsanitize=fuzzer,address,undefined) into build-fuzz/, makes
# the seed corpora from the sample cases (exported by the normal build's studio, a session report
# from its player) and fuzz_make_seeds, and runs each target for the given seconds, then prints per
# target: executions, coverage (cov), corpus size and findings (crash-*, leak-*, timeout-*, oom-*
# files in out/fuzz/<target>/findings/; an earlier run's are run again first, and move to fixed/
# once they pass). Fails when a harness does not build, has a finding or runs no input.
# scripts/test.sh runs it for 3 s per target (quick build, below), so that no harness can rot.
#
#   scripts/fuzz.sh [seconds-per-target=60] [build-dir=build] [target...]   (no target: all)
#
# VISCERA_FUZZ_QUICK=1: the harnesses built at -O0 with line tables only (VISCERA_FUZZ_QUICK, the
# same sanitizers) into build-fuzz-quick/: about half the compile time; what scripts/test.sh uses.
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${1:-60}"
build="${2:-${VISCERA_BUILD_DIR:-build}}"
shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
((${#targets[@]})) || targets=(case_package manifest signature scene scene_blocks vtet vweights console_protocol link_auth
  instrument_track device_trajectory needle_trajectory mesh_format session_report)
quick=OFF
fz=build-fuzz
[[ ${VISCERA_FUZZ_QUICK:-0} == 1 ]] && quick=ON fz=build-fuzz-quick
out=out/fuzz
# clang-14 and its libFuzzer, from Debian, where missing.
if ! command -v clang++-14 >/dev/null || [[ ! -d /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux ]] ||
   ! ls /usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "fuzz: installing clang-14 libfuzzer-14-dev"
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO=sudo
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends clang-14 libfuzzer-14-dev
fi
if [[ ! -f "$fz/build.ninja" ]]; then
  cmake -S . -B "$fz" -G Ninja -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVISCERA_BUILD_FUZZ=ON -DVISCERA_BUILD_TESTS=OFF \
    -DVISCERA_BUILD_BENCH=OFF -DVISCERA_BUILD_STUDIO=OFF -DVISCERA_BUILD_PLAYER=OFF -DVISCERA_FUZZ_QUICK=$quick >/dev/null
fi
cmake --build "$fz" -j"$(nproc)" --target viscera_fuzz
# Seeds from the samples (what a trainee's package and an artist's files look like).
seeds="$out/seeds"
rm -rf "$seeds"
mkdir -p "$seeds"/{case_package,manifest,signature,scene,vtet,vweights,instrument_track,device_trajectory,needle_trajectory,session_report}
for p in tissue-slab organ-blob anastomosis rectum liver; do
  "$build/studio/cli/viscera-studio" export "projects/$p" -o "$seeds/$p.vcase" \
    --sign-key "$build/keys/viscera-samples.pem" >/dev/null
  x="$seeds/x-$p"
  mkdir -p "$x"
  (cd "$x" && cmake -E tar xf "../$p.vcase")
  [[ $(stat -c %s "$seeds/$p.vcase") -lt 200000 ]] && cp "$seeds/$p.vcase" "$seeds/case_package/$p.vcase"
  cp "$x/manifest.json" "$seeds/manifest/$p.json"
  cp "$x/signature.json" "$seeds/signature/$p.json"
  cp "$x/scene.json" "$seeds/scene/$p.json"
  for m in $(find "$x" -name '*.vtet' -size -200k) $(find "$x" -name '*.vtri' -size -200k); do
    # First byte picks the reader: even .vtet, odd .vtri.
    { if [[ $m == *.vtri ]]; then printf '1'; else printf '0'; fi; cat "$m"; } >"$seeds/vtet/$p-$(basename "$m")"
  done
  for w in $(find "$x" -name '*.vweights' -size -200k); do
    n=$(grep -vc '^#' "$w" || true)
    { printf "\\x$(printf %02x $((n & 255)))\\x$(printf %02x $((n >> 8 & 255)))"; cat "$w"; } >"$seeds/vweights/$p-$(basename "$w")"
  done
  for t in $(find "$x" -name '*.track'); do cp "$t" "$seeds/instrument_track/$p-$(basename "$t")"; done
  for t in $(find "$x" -name '*.csv'); do cp "$t" "$seeds/needle_trajectory/$p-$(basename "$t")"; done
done
cp projects/*/replays/*.csv "$seeds/device_trajectory/"
# Session reports as the player writes them: the two samples with an assessment block, 5 frames
# each (under a second); the player's own state folder, never the user's.
key="$build/keys/viscera-samples.pem"
for p in rectum anastomosis; do
  if ! "$build/player/viscera-player" run "$seeds/$p.vcase" --trust "${key%.pem}.pub.pem" --headless --frames 5 \
    --trainee fuzz.seed --state-dir "$out/state" --report "$seeds/session_report/$p.json" >"$seeds/player-$p.log" 2>&1; then
    cat "$seeds/player-$p.log" >&2
    exit 1
  fi
done
# console_protocol/, link_auth/, mesh_format/, scene_blocks/ (from scene/), session_report/judged.json
"$fz/fuzz/fuzz_make_seeds" "$seeds" >/dev/null

status=0
printf '%-24s %12s %8s %8s %s\n' target executions cov corpus findings
for t in "${targets[@]}"; do
  dir="$out/$t"
  mkdir -p "$dir/corpus" "$dir/findings"
  dict=()
  maxlen=262144
  [[ $t == vtet ]] && maxlen=8192 # mesh seeds are large; short inputs reach the rules far faster
  case $t in
    manifest|signature|scene|scene_blocks|case_package|session_report) dict=(-dict=fuzz/dict/json.dict) ;;
    mesh_format) dict=(-dict=fuzz/dict/mesh.dict) ;;
    vtet|vweights|instrument_track|device_trajectory|needle_trajectory) dict=(-dict=fuzz/dict/text.dict) ;;
  esac
  log="$dir/run.log"
  # The findings of earlier runs first, as regression inputs: one the harness now passes moves to
  # fixed/, one it still fails on stays a finding of this run.
  : >"$dir/replay.log"
  for f in "$dir"/findings/*; do
    [[ -e $f ]] || continue
    if "$fz/fuzz/fuzz_$t" "$f" -timeout=10 -rss_limit_mb=2048 >>"$dir/replay.log" 2>&1; then
      mkdir -p "$dir/fixed"
      mv "$f" "$dir/fixed/"
    fi
  done
  "$fz/fuzz/fuzz_$t" "$dir/corpus" "$seeds/$t" "${dict[@]}" -max_total_time="$secs" -timeout=10 \
    -rss_limit_mb=2048 -max_len="$maxlen" -print_final_stats=1 -artifact_prefix="$dir/findings/" \
    >"$log" 2>&1 || true
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo 0)
  files=$(ls "$dir/corpus" | wc -l)
  findings=$(ls "$dir/findings" | wc -l)
  printf '%-24s %12s %8s %8s %s\n' "$t" "${execs:-0}" "${cov:-0}" "$files" "$findings"
  if ((findings > 0)); then
    status=1
    ls "$dir/findings" | sed 's/^/    /'
    cat "$log" "$dir/replay.log" | grep -m1 -E 'ERROR: |runtime error|SUMMARY' | sed 's/^/    /' || true
  elif ((${execs:-0} == 0)); then
    status=1
    echo "    ran no input:"
    tail -n 5 "$log" | sed 's/^/    /'
  fi
done
exit $status
