#!/usr/bin/env bash
# Haptics loopback acceptance run: viscera-console-sim streams the bimanual script over UDP to
# viscera-player (headless, real time, on the haptic sample case) and records the forces it gets
# back. Prints the servo period/jitter, the contact-model age and the console-side figures. The
# console streams until the player stops talking to it (as a real console does), so a player
# that falls behind the wall clock is judged by its own verdict, not by a link the console cut.
#
#   scripts/haptics-loopback.sh [seconds=60] [build-dir=build] [out-dir=out/haptics-loopback] [servo=shared]
#
# servo: "shared" (the player's default: SCHED_FIFO on the physics' CPUs, sleeps to each deadline; "shared:US"
# spins the last US microseconds), "sleep" (sleep, then spin the last 0.94 ms; the last CPU), "sleep:CPU" (on that CPU), "spin:US" (the same with a
# spin of US microseconds) or "busy[:CPU]" (spin the whole period on a CPU of its own; for a
# console PC with a core set aside).
# Environment: LOOPBACK_CASE=path.vcase runs that case instead of the haptic sample slab (e.g. the
# rectum, out/rectum.vcase); LOOPBACK_WINDOW=1 runs the trainee window under Xvfb (Mesa) instead of
# headless, with a screenshot of its last frame in out-dir/window.png.
set -euo pipefail
secs="${1:-60}"
build="${2:-${VISCERA_BUILD_DIR:-build}}"
out="${3:-out/haptics-loopback}"
servo="${4:-shared}"
mkdir -p "$out"
# The console is a machine of its own; here its simulator runs beside the player, so keep it off
# the CPU the player's servo thread owns (the highest allowed one, or the one the servo mode names).
# The CPUs this script may run on (taskset, cpusets), one per line; the player picks from the same.
cpus="$(awk '/^Cpus_allowed_list/ {print $2}' /proc/self/status | tr ',' '\n' |
        awk -F- '{ if (NF == 2) for (i = $1; i <= $2; i++) print i; else print $1 }')"
case "$servo" in
  shared|shared:*) servo_cpu=-1 ;;
  sleep:*|busy:*) servo_cpu="${servo#*:}" ;;
  *) if [ "$(echo "$cpus" | wc -l)" -ge 2 ]; then servo_cpu="$(echo "$cpus" | tail -n 1)"; else servo_cpu=-1; fi ;;
esac
sim_cpus=""
if [ "$servo_cpu" -ge 0 ] && command -v taskset >/dev/null; then
  sim_cpus="$(echo "$cpus" | grep -vx "$servo_cpu" | paste -sd, -)"
fi
case_file="${LOOPBACK_CASE:-$out/haptic-slab.vcase}"
# Cases are signed with the build's sample publisher key (a test key; export LOOPBACK_CASE with
# --sign-key build/keys/viscera-samples.pem) and the player trusts its public half.
key="$build/keys/viscera-samples.pem"
[ -n "${LOOPBACK_CASE:-}" ] || "$build/tests/player/make_haptic_case" "$out/haptic-slab.vcase" 2 "$key" >/dev/null
rm -f "$out/port"
# The pairing key both ends share (the authenticated link, packaging/console-protocol.md).
"$build/player/viscera-console-sim" --make-pairing-key "$out/pairing.key" >/dev/null
${sim_cpus:+taskset -c "$sim_cpus"} "$build/player/viscera-console-sim" --listen 127.0.0.1:0 --port-file "$out/port" --script bimanual --loop \
  --pairing-key "$out/pairing.key" \
  --duration "$(( secs * 4 + 10 ))" --until-player-stops --record "$out/console-forces.csv" --summary "$out/console-summary.json" \
  > "$out/console-sim.log" 2>&1 &
sim=$!
for _ in $(seq 100); do [ -s "$out/port" ] && break; sleep 0.05; done
port="$(cat "$out/port")"
frames=$(( secs * 60 ))
player_rc=0 # the figures are printed either way; the script exits with the player's status
if [ "${LOOPBACK_WINDOW:-0}" = 1 ]; then
  env -u QT_QPA_PLATFORM LIBGL_ALWAYS_SOFTWARE=1 xvfb-run -a -s "-screen 0 1920x1200x24 -nolisten tcp" \
    "$build/player/viscera-player" run "$case_file" --trust "${key%.pem}.pub.pem" --frames "$frames" --screenshot "$out/window.png" \
    --device "console:127.0.0.1:$port" --pairing-key "$out/pairing.key" --servo "$servo" --report "$out/report.json" --trace "$out/trace.csv" \
    2>/dev/null || player_rc=$?
else
  "$build/player/viscera-player" run "$case_file" --trust "${key%.pem}.pub.pem" --headless --frames "$frames" \
    --device "console:127.0.0.1:$port" --pairing-key "$out/pairing.key" --servo "$servo" --report "$out/report.json" --trace "$out/trace.csv" \
    2>/dev/null || player_rc=$?
fi
wait "$sim"
cat "$out/console-sim.log" | grep -v '^viscera-console-sim:'
python3 - "$out/report.json" <<'PY'
import json, sys
h = json.load(open(sys.argv[1]))["haptics"]
s, c = h["servo"], h["contact_model"]
print(f"servo         {s['ticks']} ticks, wait {s['wait']} (cpu {s['cpu']}), realtime priority {s['realtime_priority']}, overruns {s['overruns']}")
if 'priority_note' in s: print(f"              {s['priority_note']}")
print(f"period (us)   mean {s['period_us']['mean']:.2f}  p50 {s['period_us']['p50']:.0f}  p99 {s['period_us']['p99']:.0f}  max {s['period_us']['max']:.1f}")
print(f"jitter (us)   mean {s['jitter_us']['mean']:.2f}  p99 {s['jitter_us']['p99']:.0f}  max {s['jitter_us']['max']:.1f}")
print(f"wake (us)     p99 {s['wake_latency_us']['p99']:.0f}  max {s['wake_latency_us']['max']:.1f};  tick cost p99 {s['tick_cost_us']['p99']:.0f} us")
print(f"contact model age (ms) mean {c['age_ms']['mean']:.2f}  p99 {c['age_ms']['p99']:.2f}  max {c['age_ms']['max']:.2f}"
      f"  (physics period {c['physics_period_ms']:.2f} ms; max/period {c['max_age_over_period']:.2f}; steps behind <= {c['max_steps_behind']})")
o = c['handover']
print(f"hand-over     {o['ticks_on_older_model']} of {o['ticks_checked']} ticks used an older model than the newest published;"
      f" age <= {o['max_age_over_step']:.4f} of the physics step in progress")
p = o['physics_step_ms']
print(f"physics step  (publish to publish, ms) mean {p['mean']:.2f}  p99 {p['p99']:.2f}  max {p['max']:.2f};"
      f" {o['steps_over_period']} of {o['models_published'] - 1} over the period")
print(f"safety        {h['safety']}")
print(f"link          {h['link']}")
PY
echo "files         $out/{report.json,trace.csv,console-forces.csv,console-summary.json}"
exit "$player_rc"
