#!/usr/bin/env bash
# How fast an unsigned package that expands to 1 GiB is refused (issue 58): wall time and peak
# memory of `viscera-player verify` and of `viscera-launcher --list` over a folder holding it
# (GNU time). The package is made by make_unsigned_bomb.py (11 MB, 93:1).
#
#   bench/trust/time_refusal.sh [build-dir=build]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
command -v /usr/bin/time >/dev/null || { echo "time_refusal: needs GNU time (apt-get install time)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/cases" "$work/cache"
python3 bench/trust/make_unsigned_bomb.py "$work/cases/bomb.vcase"
measure() { # label, command...
  local label=$1
  shift
  local rc=0
  /usr/bin/time -f '%e %M' -o "$work/time" "$@" >"$work/out" 2>"$work/err" || rc=$?
  read -r secs kib < <(tail -1 "$work/time") # GNU time first notes a non-zero exit
  printf '%-34s exit %d  %6.2f s  %6.1f MB  %s\n' "$label" "$rc" "$secs" "$(echo "$kib / 1024" | bc -l)" \
    "$(cat "$work/err" "$work/out" | head -c 200 | tr '\n' ' ')"
}
measure "player verify (unsigned 1 GiB)" "$build/player/viscera-player" verify "$work/cases/bomb.vcase" \
  --state-dir "$work/state"
measure "launcher --list (its folder)" env XDG_CACHE_HOME="$work/cache" "$build/launcher/viscera-launcher" \
  --list "$work/cases"
# For contrast, the same package admitted (--allow-unsigned): now every entry is inflated and
# hashed, as every package was before the admission moved ahead of step f.
measure "player verify --allow-unsigned" "$build/player/viscera-player" verify "$work/cases/bomb.vcase" \
  --allow-unsigned --state-dir "$work/state"
