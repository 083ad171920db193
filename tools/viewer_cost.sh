#!/usr/bin/env bash
# What stewart_viewer with one headless browser attached costs the real-time
# loop (docs/performance.md, "The viewer's cost"): N pairs of real-time paper
# runs, alternating without and with the viewer + browser, back to back.
# Prints one line per run: latency p50/p99/max, missed ticks, the viewer's
# CPU time.
#   tools/viewer_cost.sh [PAIRS=3] [DURATION_S=20] [OUT=/tmp/viewer_cost] [BROWSER_CPUS]
# BROWSER_CPUS (e.g. 0): run the browser on these CPUs only (taskset), off
# the loop's CPU; default: wherever the scheduler puts it; "none": no
# browser, the viewer alone.
set -euo pipefail
cd "$(dirname "$0")/.."
PAIRS=${1:-3} DURATION=${2:-20} OUT=${3:-/tmp/viewer_cost} BROWSER_CPUS=${4:-}
BROWSER_PIN=()
[[ -z $BROWSER_CPUS || $BROWSER_CPUS == none ]] || BROWSER_PIN=(taskset -c "$BROWSER_CPUS")
BUILD=${STEWART_BUILD_DIR:-build}
PORT=18980
mkdir -p "$OUT"
run() { # index, with_viewer
  local dir="$OUT/run$1-$([[ $2 == 1 ]] && echo viewer || echo plain)"
  rm -rf "$dir"
  local extra=() watcher=""
  if [[ $2 == 1 ]]; then
    extra=(--viewer-port "$PORT")
  fi
  if [[ $2 == 1 && $BROWSER_CPUS != none ]]; then
    # The browser attaches once the viewer listens, and watches the whole run.
    (for _ in $(seq 100); do bash -c "exec 3<>/dev/tcp/127.0.0.1/$PORT" 2>/dev/null && break; sleep 0.1; done
     "${BROWSER_PIN[@]}" node tests/viewer/browser/watch.js "http://127.0.0.1:$PORT/" "$((DURATION + 2))") >"$OUT/watch$1.log" 2>&1 &
    watcher=$!
  fi
  STEWART_BUILD_DIR=$BUILD tools/launch.sh --no-build --no-report --realtime --scenario paper \
    --duration "$DURATION" --out "$dir" --lcm-url "udpm://239.255.76.67:7980?ttl=0" "${extra[@]}" >/dev/null
  [[ -z $watcher ]] || wait "$watcher" || true
  local lat missed cpu
  lat=$(grep -o 'latency p50 [0-9]* us, p99 [0-9]* us, max [0-9]* us' "$dir/plant_sim.log" | tail -1)
  missed=$(grep -o 'missed ticks [0-9]*' "$dir/plant_sim.log" | tail -1)
  cpu=$(grep -o 'viewer_cpu_s: [0-9.]*' "$dir/run.yaml" || echo "viewer_cpu_s: -")
  echo "run $1 viewer=$2: $lat; $missed; $cpu; $(cat "$OUT/watch$1.log" 2>/dev/null || true)"
}
for i in $(seq "$PAIRS"); do
  run "$((2 * i - 1))" 0
  run "$((2 * i))" 1
done
