#!/usr/bin/env bash
# Fuzzes every reader of outside input with libFuzzer [issue 19]: builds the harnesses of fuzz/
# with clang-14 (-fsanitize=fuzzer,address,undefined) into build-fuzz/, makes the seed corpora
# from the sample cases (exported by the normal build's studio) and runs each target for the
# given seconds, then prints per target: executions, coverage (cov), corpus size and findings
# (crash-*, leak-*, timeout-*, oom-* files in out/fuzz/<target>/).
#
#   scripts/fuzz.sh [seconds-per-target=60] [build-dir=build] [target...]   (no target: all)
set -euo pipefail
cd "$(dirname "$0")/.."
secs="${1:-60}"
build="${2:-${VISCERA_BUILD_DIR:-build}}"
shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
((${#targets[@]})) || targets=(case_package manifest scene vtet vweights console_protocol instrument_track device_trajectory needle_trajectory mesh_format)
fz=build-fuzz
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
    -DVISCERA_BUILD_BENCH=OFF -DVISCERA_BUILD_STUDIO=OFF -DVISCERA_BUILD_PLAYER=OFF >/dev/null
fi
cmake --build "$fz" -j"$(nproc)" --target viscera_fuzz
# Seeds from the samples (what a trainee's package and an artist's files look like).
seeds="$out/seeds"
rm -rf "$seeds"
mkdir -p "$seeds"/{case_package,manifest,scene,vtet,vweights,console_protocol,instrument_track,device_trajectory,needle_trajectory}
for p in tissue-slab organ-blob anastomosis rectum liver; do
  "$build/studio/cli/viscera-studio" export "projects/$p" -o "$seeds/$p.vcase" \
    --sign-key "$build/keys/viscera-samples.pem" >/dev/null 2>&1
  x="$seeds/x-$p"
  mkdir -p "$x"
  (cd "$x" && cmake -E tar xf "../$p.vcase")
  [[ $(stat -c %s "$seeds/$p.vcase") -lt 200000 ]] && cp "$seeds/$p.vcase" "$seeds/case_package/$p.vcase"
  cp "$x/manifest.json" "$seeds/manifest/$p.json"
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
"$fz/fuzz/fuzz_make_seeds" "$seeds" >/dev/null # console_protocol/, mesh_format/

status=0
printf '%-24s %12s %8s %8s %s\n' target executions cov corpus findings
for t in "${targets[@]}"; do
  dir="$out/$t"
  mkdir -p "$dir/corpus" "$dir/findings"
  dict=()
  maxlen=262144
  [[ $t == vtet ]] && maxlen=8192 # mesh seeds are large; short inputs reach the rules far faster
  case $t in
    manifest|scene|case_package) dict=(-dict=fuzz/dict/json.dict) ;;
    mesh_format) dict=(-dict=fuzz/dict/mesh.dict) ;;
    vtet|vweights|instrument_track|device_trajectory|needle_trajectory) dict=(-dict=fuzz/dict/text.dict) ;;
  esac
  log="$dir/run.log"
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
    grep -m1 -E 'ERROR: |runtime error|SUMMARY' "$log" | sed 's/^/    /' || true
  fi
done
exit $status
