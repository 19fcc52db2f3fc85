#!/usr/bin/env bash
# Soak run [issue 19 item 4]: the rectum and anastomosis samples back to back in one player process
# (headless, their committed replays, stepped with the physics) for most of the time, a line per
# minute (frames, all finite, energy against each case's first pass, resident memory), then the
# console loopback on the rectum for the last part (viscera-console-sim ⇄ viscera-player over UDP,
# real time). Prints the resident-memory growth from minute 5 to the end.
#
#   scripts/soak.sh [minutes=60] [build-dir=build] [out-dir=out/soak]
set -euo pipefail
cd "$(dirname "$0")/.."
minutes="${1:-60}"
build="${2:-${VISCERA_BUILD_DIR:-build}}"
out="${3:-out/soak}"
mkdir -p "$out"
key="$build/keys/viscera-samples.pem" # the build's sample publisher key (a test key)
for p in rectum anastomosis; do
  "$build/studio/cli/viscera-studio" export "projects/$p" -o "$out/$p.vcase" --sign-key "$key" >/dev/null 2>&1 ||
    { echo "soak: cannot export projects/$p" >&2; exit 1; }
done
# The last tenth (at least a minute, at most 10) on the console loopback.
loop=$(( minutes / 10 )); ((loop >= 1)) || loop=1; ((loop <= 10)) || loop=10
soak=$(( minutes - loop )); ((soak >= 1)) || soak=1
status=0
"$build/player/viscera-player" soak \
  "$out/rectum.vcase@replay:projects/rectum/replays/dissection.csv" \
  "$out/anastomosis.vcase@replay:projects/anastomosis/replays/running-suture.csv" \
  --minutes "$soak" --frames 330 --report "$out/soak.json" --trust "${key%.pem}.pub.pem" 2>/dev/null || status=$?
echo "== console loopback, rectum, $loop min =="
rm -f "$out/port" "$out/pairing.key"
"$build/player/viscera-console-sim" --make-pairing-key "$out/pairing.key" >/dev/null
"$build/player/viscera-console-sim" --listen 127.0.0.1:0 --port-file "$out/port" --pairing-key "$out/pairing.key" \
  --trajectory projects/rectum/replays/dissection.csv --loop --duration $(( loop * 60 + 1 )) \
  --record "$out/console-forces.csv" --summary "$out/console-summary.json" > "$out/console-sim.log" 2>&1 &
sim=$!
for _ in $(seq 100); do [ -s "$out/port" ] && break; sleep 0.05; done
# Frames for the loopback's wall time at the rectum's physics rate (it runs below real time).
"$build/player/viscera-player" run "$out/rectum.vcase" --headless --frames $(( loop * 60 * 20 )) \
  --device "console:127.0.0.1:$(cat "$out/port")" --pairing-key "$out/pairing.key" --trust "${key%.pem}.pub.pem" \
  --report "$out/loopback.json" 2>/dev/null |
  grep -E '^(frames|status|real time|device force|haptics)' || status=1
kill "$sim" 2>/dev/null || true
wait "$sim" 2>/dev/null || true
grep -E '^(console-sim|latency)' "$out/console-sim.log" || true
exit $status
