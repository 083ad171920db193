#!/usr/bin/env bash
# tools/lcm-spy, headless: starts Xvfb and lcm-spy on a private LCM URL,
# publishes every stewart type, and checks that
#   - lcm-spy loaded every type of lcmtypes/*.lcm ("Found N LCM types"),
#   - its window is up and it neither died nor printed a decode exception,
#   - every channel decodes to the right class through lcm-spy's own type
#     database on the same classpath (SpyDecodeCheck.java).
# Usage: lcm_spy_test.sh PUBLISHER [SCREENSHOT.png]
# Exit 77 (ctest SKIP) only when Xvfb or java is absent.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
PUBLISHER=${1:?usage: $0 PUBLISHER [SCREENSHOT.png]}
SCREENSHOT=${2:-}
URL="udpm://239.255.76.67:7790?ttl=0"

for tool in Xvfb java xwininfo; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool not installed"; exit 77; }
done

TMP=$(mktemp -d)
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$TMP"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  echo "--- lcm-spy output:"; cat "$TMP/spy.log" 2>/dev/null || true
  echo "--- decode check output:"; cat "$TMP/check.log" 2>/dev/null || true
  exit 1
}
wait_for() {  # wait_for SECONDS COMMAND...
  local end=$((SECONDS + $1)); shift
  until "$@"; do ((SECONDS < end)) || return 1; sleep 0.2; done
}

# Xvfb picks a free display and writes its number to fd 3 once it is ready.
Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>"$TMP/display" 2>"$TMP/xvfb.log" &
PIDS+=($!)
wait_for 10 test -s "$TMP/display" || fail "Xvfb did not start: $(cat "$TMP/xvfb.log")"
export DISPLAY=":$(head -n 1 "$TMP/display")"

"$ROOT/tools/lcm-spy" --lcm-url="$URL" >"$TMP/spy.log" 2>&1 &
SPY_PID=$!
PIDS+=("$SPY_PID")
NUM_TYPES=$(find "$ROOT/lcmtypes" -maxdepth 1 -name '*.lcm' | wc -l)
wait_for 30 grep -q "Found [0-9]* LCM types" "$TMP/spy.log" || fail "lcm-spy did not load types"
grep -q "Found $NUM_TYPES LCM types" "$TMP/spy.log" ||
  fail "lcm-spy should find the $NUM_TYPES stewart types: $(grep 'LCM types' "$TMP/spy.log")"
wait_for 20 sh -c 'xwininfo -root -tree | grep -q "\"LCM Spy\""' || fail "no 'LCM Spy' window"

mapfile -t CHANNEL_LINES < <("$PUBLISHER" --channels)
CHANNELS=()
for line in "${CHANNEL_LINES[@]}"; do CHANNELS+=("${line%% *}"); done
CLASSPATH_SPY=$("$ROOT/tools/lcm-spy" --print-classpath)
java -Djava.net.preferIPv4Stack=true -cp "$CLASSPATH_SPY" "$ROOT/tests/spy/SpyDecodeCheck.java" \
  "$URL" 20 "${CHANNELS[@]}" >"$TMP/check.log" 2>&1 &
CHECK_PID=$!
PIDS+=("$CHECK_PID")
wait_for 30 grep -q ready "$TMP/check.log" || fail "decode check did not start"

"$PUBLISHER" "$URL" 60 50 >"$TMP/publisher.log" 2>&1 || fail "publisher: $(cat "$TMP/publisher.log")"
wait "$CHECK_PID" || fail "not every channel decoded"

for line in "${CHANNEL_LINES[@]}"; do
  channel=${line%% *} type=${line##* }
  grep -q "^decoded $channel stewart.$type utime=" "$TMP/check.log" ||
    fail "$channel should decode as stewart.$type"
done
kill -0 "$SPY_PID" 2>/dev/null || fail "lcm-spy died"
if grep -qE "messageReceived ex|Exception" "$TMP/spy.log"; then fail "lcm-spy reported an error"; fi

if [[ -n "$SCREENSHOT" ]]; then
  sleep 1  # let the table repaint with the last rates
  /usr/bin/python3 -c "import sys; from PIL import ImageGrab; \
ImageGrab.grab(xdisplay=sys.argv[1]).save(sys.argv[2])" "$DISPLAY" "$SCREENSHOT" ||
    fail "screenshot failed"
fi
echo "PASS: lcm-spy found $NUM_TYPES types; decoded ${#CHANNELS[@]} channels: ${CHANNELS[*]}"
