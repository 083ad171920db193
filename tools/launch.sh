#!/usr/bin/env bash
# Starts the stack: plant (plant_sim, or hw_bridge with --plant hw), estimator,
# controller and safety, with one config and one scenario, on a private LCM
# URL. With no arguments: the simulated stack on the paper's scenario, in
# lockstep, recorded, with a report. See docs/operations.md.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"

usage() {
  cat <<USAGE
usage: tools/launch.sh [options]
  --plant sim|hw        simulator (default) or the hardware bridge
  --device-emulator     with --plant hw: also start the device emulator (no real device)
  --lockstep            plant and stack step together (default for sim)
  --realtime            wall-clock paced at the sensor rate (default for hw)
  --scenario NAME|FILE  config/scenarios/NAME.yaml (default: paper)
  --config FILE         stack config (default: config/platform.yaml)
  --overlay FILE        YAML overlay: its keys replace the config's (repeatable, applied
                        in order; the run folder's config.yaml is the merged config)
  --truth FILE          the plant's physics differ from the config (plant_sim or the
                        device emulator only; docs/simulation.md, "Truth")
  --seed N              sensor noise and disturbance seed of the simulated plant
  --variant V           safety filter: closed_form | paper | qp | uncomposed (default: from config)
  --duration S          simulated seconds (default: the scenario's duration)
  --log FILE            record every channel to FILE (default: <run>/log.lcm), with
                        stewart_logger (or lcm-logger with --lcm-logger)
  --no-log              do not record (no report either)
  --no-report           record, but do not write the report
  --spy                 also open lcm-spy on the run's URL
  --viewer              also start stewart_viewer (read-only) on the run's URL: the page at
                        http://127.0.0.1:8080/ (docs/operations.md, "The viewer")
  --viewer-port N       its port (default: viewer.port of the config, 8080)
  --lcm-url URL         use this URL instead of a private one
  --out DIR             run folder (default: runs/<date>-<scenario>)
  --no-build            use the build as it is (skip tools/setup.sh; tests use this)
  --lcm-logger          record with the packaged lcm-logger instead of stewart_logger
  --rt-priority P       SCHED_FIFO priority of plant, estimator, controller and safety
                        (default: 50 in real time when permitted, else 0 = normal scheduling)
  --loop-cpu N|auto|none  run those four on CPU N (auto: the last CPU when there are two
                        or more; none: let the scheduler place them)
  --hosts FILE          start each process on its host (ip netns exec here, ssh in a
                        deployment): docs/operations.md, "Several hosts"; needs --lcm-url
                        with ttl=1
  --check-network       check the bus (route, ttl, who hears whom; with --hosts, between
                        every pair of hosts) and exit
USAGE
}

PLANT=sim MODE="" SCENARIO=paper CONFIG="$ROOT/config/platform.yaml" VARIANT="" DURATION=""
VIEWER=0 VIEWER_PORT="" LOG="" DO_LOG=1 DO_REPORT=1 SPY=0 URL="" OUT="" EMULATOR=0 BUILD_FIRST=1 LCM_LOGGER=0 RT_PRIORITY='' LOOP_CPU=auto
TRUTH="" SEED= HOSTS_FILE="" CHECK_NETWORK=0
OVERLAYS=()
ARGS="$*"
while (($#)); do
  case "$1" in
    --plant) PLANT=$2; shift ;;
    --device-emulator) EMULATOR=1 ;;
    --lockstep) MODE=lockstep ;;
    --realtime) MODE=realtime ;;
    --scenario) SCENARIO=$2; shift ;;
    --config) CONFIG=$(realpath "$2"); shift ;;
    --overlay) [[ -f $2 ]] || { echo "launch: overlay '$2' not found" >&2; exit 2; }
               OVERLAYS+=("$(realpath "$2")"); shift ;;
    --variant) VARIANT=$2; shift ;;
    --truth) TRUTH=$(realpath "$2") || exit 2; shift ;;
    --seed) SEED=$2; shift ;;
    --duration) DURATION=$2; shift ;;
    --log) LOG=$(realpath -m "$2"); shift ;;
    --no-log) DO_LOG=0; DO_REPORT=0 ;;
    --no-report) DO_REPORT=0 ;;
    --spy) SPY=1 ;;
    --viewer) VIEWER=1 ;;
    --viewer-port) VIEWER=1; VIEWER_PORT=$2; shift ;;
    --lcm-url) URL=$2; shift ;;
    --out) OUT=$(realpath -m "$2"); shift ;;
    --no-build) BUILD_FIRST=0 ;;
    --lcm-logger) LCM_LOGGER=1 ;;
    --rt-priority) RT_PRIORITY=$2; shift ;;
    --loop-cpu) LOOP_CPU=$2; shift ;;
    --hosts) [[ -f $2 ]] || { echo "launch: hosts file '$2' not found" >&2; exit 2; }
             HOSTS_FILE=$(realpath "$2"); shift ;;
    --check-network) CHECK_NETWORK=1 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "launch: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
[[ $PLANT == sim || $PLANT == hw ]] || { echo "launch: --plant sim|hw" >&2; exit 2; }
[[ -n $MODE ]] || { [[ $PLANT == sim ]] && MODE=lockstep || MODE=realtime; }
if [[ -n $TRUTH && $PLANT == hw && $EMULATOR == 0 ]]; then
  echo "launch: --truth describes a simulated plant: use --plant sim or --device-emulator" >&2; exit 2
fi
# Where each process runs (--hosts): HOST_PREFIX[host] is the command that
# starts a program on that host, PROCESS_HOST[process] its host; a process
# the file does not name runs here.
declare -A HOST_PREFIX=() PROCESS_HOST=()
KNOWN_PROCESSES=" plant_sim hw_bridge hw_emulator estimator controller safety logger monitor lcm-spy viewer "
if [[ -n $HOSTS_FILE ]]; then
  line_no=0
  while IFS= read -r line || [[ -n $line ]]; do
    line_no=$((line_no + 1))
    line=${line%%#*}
    read -ra words <<<"$line"
    ((${#words[@]})) || continue
    where="launch: $HOSTS_FILE:$line_no"
    case "${words[0]}" in
      host) ((${#words[@]} >= 2)) || { echo "$where: 'host NAME [COMMAND PREFIX...]'" >&2; exit 2; }
            HOST_PREFIX[${words[1]}]="${words[*]:2}" ;;
      run) ((${#words[@]} == 3)) || { echo "$where: 'run PROCESS HOST'" >&2; exit 2; }
           [[ $KNOWN_PROCESSES == *" ${words[1]} "* ]] ||
             { echo "$where: unknown process '${words[1]}' (one of:$KNOWN_PROCESSES)" >&2; exit 2; }
           [[ -n ${HOST_PREFIX[${words[2]}]+set} ]] ||
             { echo "$where: host '${words[2]}' is not defined above ('host ${words[2]} ...')" >&2; exit 2; }
           PROCESS_HOST[${words[1]}]=${words[2]} ;;
      *) echo "$where: a line is 'host NAME PREFIX...' or 'run PROCESS HOST', not '${words[0]}'" >&2; exit 2 ;;
    esac
  done <"$HOSTS_FILE"
  ((${#PROCESS_HOST[@]})) || { echo "launch: $HOSTS_FILE places no process ('run PROCESS HOST')" >&2; exit 2; }
  # Across hosts the datagrams must pass one router hop at least, and the
  # group is the user's choice for their network, never a default.
  [[ -n $URL ]] || { echo "launch: --hosts needs --lcm-url (the group and port of your network, ttl=1)" >&2; exit 2; }
  [[ $URL =~ [?\&]ttl=([1-9][0-9]*) ]] ||
    { echo "launch: with --hosts the URL needs ttl=1 or more (ttl=0 keeps every datagram on its own host): $URL" >&2; exit 2; }
fi
on_host() { # process name: the words that start a program on its host (none: here)
  local host=${PROCESS_HOST[$1]:-}
  [[ -n $host ]] && echo "${HOST_PREFIX[$host]}"
  return 0
}
if [[ $PLANT == hw && $MODE == lockstep ]]; then
  echo "launch: the real device cannot step in lockstep; use --realtime" >&2; exit 2
fi
# The loop's processes preempt everything else (logger, monitor, builds) in
# real time: a control tick must not wait behind a recorder's disk write.
if [[ -z $RT_PRIORITY ]]; then
  RT_PRIORITY=0
  if [[ $MODE == realtime ]] && chrt -f 1 true 2>/dev/null; then RT_PRIORITY=50; fi
fi
[[ $RT_PRIORITY =~ ^[0-9]+$ && $RT_PRIORITY -le 99 ]] || { echo "launch: --rt-priority 0..99" >&2; exit 2; }
RT=()
if ((RT_PRIORITY > 0)); then
  chrt -f "$RT_PRIORITY" true 2>/dev/null ||
    { echo "launch: SCHED_FIFO $RT_PRIORITY not permitted (root or CAP_SYS_NICE / rtprio limit)" >&2; exit 2; }
  RT=(chrt -f "$RT_PRIORITY")
fi
# The loop is a chain (plant -> estimator -> controller -> safety -> plant):
# on one CPU each hop is a plain context switch, across CPUs it is an
# inter-processor wake-up, which on a virtual machine costs tens of us
# (docs/performance.md, "Stack end to end"). The emulator (a stand-in for the
# device's own processor) and the recorder stay off that CPU's schedule.
if [[ $LOOP_CPU == auto ]]; then
  LOOP_CPU=none
  CPUS=$(nproc 2>/dev/null || echo 1)
  if ((CPUS >= 2)) && command -v taskset >/dev/null; then LOOP_CPU=$((CPUS - 1)); fi
fi
PIN=()
if [[ $LOOP_CPU != none ]]; then
  [[ $LOOP_CPU =~ ^[0-9]+$ ]] || { echo "launch: --loop-cpu N|auto|none" >&2; exit 2; }
  taskset -c "$LOOP_CPU" true 2>/dev/null || { echo "launch: cannot pin to CPU $LOOP_CPU" >&2; exit 2; }
  PIN=(taskset -c "$LOOP_CPU")
fi
LOOP=("${PIN[@]}" "${RT[@]}")

((BUILD_FIRST)) && tools/setup.sh >/dev/null
BUILD=${STEWART_BUILD_DIR:-$ROOT/build}
bin() { # path of a built program, or fail naming it
  local p
  p=$(find "$BUILD" -maxdepth 3 -type f -name "$1" -perm -u+x -print -quit)
  [[ -n $p ]] || { echo "launch: program '$1' is not built in $BUILD" >&2; exit 1; }
  echo "$p"
}
# --check-network: is there a route for the group, does each host hear
# every host (itself included: the loopback of multicast)? A missing route,
# ttl=0 across hosts and a firewall rule are named; exit 0 when all hear all.
check_network() {
  local url=${URL:-udpm://239.255.76.67:7667?ttl=0}
  local group=${url#udpm://}
  group=${group%%[:?]*}
  local ttl=0
  [[ $url =~ [?\&]ttl=([0-9]+) ]] && ttl=${BASH_REMATCH[1]}
  local hosts=(here) h prefix route dev ok=1 tmp
  [[ -z $HOSTS_FILE ]] || mapfile -t hosts < <(printf '%s\n' "${!HOST_PREFIX[@]}" | sort)
  tmp=$(mktemp -d)
  echo "== network check: $url, hosts: ${hosts[*]} =="
  if ((${#hosts[@]} > 1 && ttl == 0)); then
    echo "  ttl=0 keeps every datagram on its own host: use ttl=1 in the URL"; ok=0
  fi
  for h in "${hosts[@]}"; do
    prefix=()
    [[ $h == here ]] || read -ra prefix <<<"${HOST_PREFIX[$h]}"
    if ! route=$("${prefix[@]}" ip route get "$group" 2>&1); then
      echo "  $h: no route for $group ($route): add one, e.g. 'ip route add 224.0.0.0/4 dev IFACE' (IFACE: the interface on the stack's network; lo for one machine)"
      ok=0; continue
    fi
    dev=$(sed -n 's/.* dev \([^ ]*\).*/\1/p' <<<"$route" | head -n 1)
    echo "  $h: $group leaves by ${dev:-?}"
    if ((${#hosts[@]} > 1)) && [[ $dev == lo ]]; then echo "    lo never reaches another host"; ok=0; fi
    "${prefix[@]}" "$(bin stewart_netcheck)" --lcm-url "$url" --id "$h" --duration-s 2 \
      >"$tmp/$h.out" 2>"$tmp/$h.err" &
  done
  wait || true
  local r s heard sent
  for r in "${hosts[@]}"; do
    [[ -f $tmp/$r.out ]] || continue
    if [[ -s $tmp/$r.err ]]; then echo "  $r: $(head -n 1 "$tmp/$r.err")"; ok=0; continue; fi
    for s in "${hosts[@]}"; do
      # A host without a route sent nothing: no file (and no exit under set -e).
      sent=$(awk '$1 == "sent" { print $2 }' "$tmp/$s.out" 2>/dev/null || true)
      heard=$(awk -v s="$s" '$1 == "heard" && $2 == s { print $3 }' "$tmp/$r.out" || true)
      if [[ -z $sent ]]; then echo "  $r hears $s: $s sent no probes"; ok=0; continue; fi
      echo "  $r hears $s: ${heard:-0} of $sent probes"
      if [[ -z $heard ]]; then ok=0; fi
    done
  done
  # A host that hears less than all may have a packet filter: name the
  # rules that drop or reject (iptables, either backend; nft's own tables).
  if ((!ok)); then
    for h in "${hosts[@]}"; do
      prefix=()
      [[ $h == here ]] || read -ra prefix <<<"${HOST_PREFIX[$h]}"
      local rules=""
      if command -v iptables >/dev/null; then
        rules=$("${prefix[@]}" iptables -S 2>/dev/null | grep -E -- '-P (INPUT|OUTPUT) DROP|-j (DROP|REJECT)' || true)
      fi
      if [[ -z $rules ]] && command -v nft >/dev/null; then
        rules=$("${prefix[@]}" nft list ruleset 2>/dev/null | grep -E '(^|[[:space:]])(drop|reject)([[:space:]]|;|$)' || true)
      fi
      [[ -n $rules ]] || continue
      echo "  $h: a firewall rule drops packets (iptables -S / nft list ruleset): allow UDP to the URL's port and IGMP"
      sed 's/^/      /' <<<"$rules" | head -n 5
    done
  fi
  rm -rf "$tmp"
  if ((ok)); then echo "network check: every host hears every host"; return 0; fi
  echo "network check: FAILED (docs/operations.md, \"Several hosts\")"; return 1
}
if ((CHECK_NETWORK)); then check_network; exit $?; fi

PLANT_SIM=$(bin plant_sim) ESTIMATOR=$(bin estimator) CONTROLLER=$(bin controller)
SAFETY=$(bin safety) MONITOR=$(bin stewart_stack_monitor) LOGGER=$(bin stewart_logger)

STAMP=$(date +%Y%m%d-%H%M%S)
[[ -n $OUT ]] || OUT="$ROOT/runs/$STAMP-$(basename "$SCENARIO" .yaml)"
mkdir -p "$OUT"
# Everything needed to reproduce the run sits beside the log. With overlays
# the config.yaml there is the merged config every process loads (each gets
# the file and the overlays: a plant's truth overrides the file, not what
# the overlays make the stack believe), so replay and the report read what ran.
# Supervision and trust (docs/operations.md): a key per run folder for the
# authenticated channels (CMD_SAFE, SUPERVISOR, OPERATOR), and in simulation
# (plant_sim or the device emulator) a supervisor that arms by itself. On a
# real device the stack starts DISARMED: an operator arms it. This overlay
# comes first, so the user's overlays can override it.
(umask 077 && od -An -tx1 -N32 /dev/urandom | tr -d ' \n' >"$OUT/auth.key")
SIMULATED=$([[ $PLANT == sim || $EMULATOR == 1 ]] && echo true || echo false)
{
  echo "# written by tools/launch.sh"
  echo "lcm:"
  echo "  auth_key_file: \"$OUT/auth.key\""
  echo "supervisor:"
  echo "  auto_arm: $SIMULATED"
  # In lockstep the plant waits for the stack's command: a safety process
  # that reads a state late (a loaded host) stalls nothing, and is no fault.
  [[ $MODE == lockstep ]] && echo "  stall_check: false"
} >"$OUT/launch-overlay.yaml"
OVERLAY_ARGS=(--overlay "$OUT/launch-overlay.yaml")
for f in "${OVERLAYS[@]}"; do OVERLAY_ARGS+=(--overlay "$f"); done
"$(bin stewart_config_merge)" --config "$CONFIG" "${OVERLAY_ARGS[@]}" --out "$OUT/config.yaml" ||
  { echo "launch: the overlays do not apply to $CONFIG" >&2; exit 2; }
[[ -n $DURATION ]] || DURATION=$("$CONTROLLER" --config "$CONFIG" "${OVERLAY_ARGS[@]}" --scenario "$SCENARIO" --print-duration)
[[ -n $LOG ]] || LOG="$OUT/log.lcm"
if [[ -z $URL ]]; then
  # A private multicast port per run (ttl=0: nothing leaves this machine).
  URL="udpm://239.255.76.67:$((20000 + RANDOM % 20000))?ttl=0"
fi
COMMON=(--config "$CONFIG" "${OVERLAY_ARGS[@]}" --lcm-url "$URL")

if [[ -f $SCENARIO ]]; then cp "$SCENARIO" "$OUT/scenario.yaml"
else cp "$ROOT/config/scenarios/$SCENARIO.yaml" "$OUT/scenario.yaml"; fi
{
  echo "git_revision: $(git rev-parse HEAD 2>/dev/null || echo unknown)$(git diff --quiet 2>/dev/null || echo '-dirty')"
  echo "started: $STAMP"
  echo "plant: $PLANT"
  echo "mode: $MODE"
  echo "scenario: $SCENARIO"
  echo "duration_s: $DURATION"
  echo "variant: ${VARIANT:-from config}"
  echo "launch_overlay: $OUT/launch-overlay.yaml"
  ((${#OVERLAYS[@]})) && echo "overlays: [$(IFS=,; echo "${OVERLAYS[*]}" | sed 's/,/, /g')]"
  echo "rt_priority: $RT_PRIORITY"
  echo "loop_cpu: $LOOP_CPU"
  echo "lcm_url: $URL"
  [[ -z $HOSTS_FILE ]] || echo "hosts: $HOSTS_FILE"
  echo "command: tools/launch.sh $ARGS"
} > "$OUT/run.yaml"

echo "== Stewart stack: $PLANT, $MODE, scenario '$SCENARIO' ($DURATION s) =="
echo "   run folder: $OUT"
echo "   LCM URL:    $URL"
if [[ -n $HOSTS_FILE ]]; then
  for p in "${!PROCESS_HOST[@]}"; do echo "   host:       $p on ${PROCESS_HOST[$p]} (${HOST_PREFIX[${PROCESS_HOST[$p]}]:-here})"; done
fi
((RT_PRIORITY > 0)) && echo "   scheduling: SCHED_FIFO $RT_PRIORITY for the loop's processes"
[[ $LOOP_CPU != none ]] && echo "   loop CPU:   $LOOP_CPU (plant, estimator, controller, safety)"
echo "   process logs: $OUT/<process>.log"
if [[ $SIMULATED == true ]]; then
  echo "   supervisor: arms automatically (simulation; supervisor.auto_arm)"
else
  echo "   supervisor: DISARMED until you arm: $(bin stewart_ctl) arm --config $OUT/config.yaml --lcm-url '$URL'"
fi

PIDS=() NAMES=()
start() { # name, command... (on the process's host with --hosts)
  local name=$1; shift
  local prefix=()
  read -ra prefix <<<"$(on_host "$name")"
  # ssh hands its command to the remote shell as one string: quote each word
  # (a URL's '?' and '&' must reach the program as they are).
  if [[ ${prefix[0]:-} == ssh ]]; then set -- "$(printf '%q ' "$@")"; fi
  "${prefix[@]}" "$@" >"$OUT/$name.log" 2>&1 &
  PIDS+=($!) NAMES+=("$name")
}
stop_all() {
  local pid
  for pid in "${PIDS[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for _ in $(seq 30); do
    local alive=0
    for pid in "${PIDS[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    ((alive)) || return 0
    sleep 0.1
  done
  for pid in "${PIDS[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
}
fail() { # name of the process that died
  echo "launch: '$1' exited unexpectedly; its last log lines:" >&2
  tail -n 15 "$OUT/$1.log" >&2 || true
  stop_all
  exit 1
}
trap 'echo; echo "launch: interrupted, stopping every process"; stop_all; exit 130' INT TERM
# A reader that goes away (`tools/launch.sh | head`) or a closed terminal:
# stop every process before exiting, and on any other exit path too.
trap 'stop_all; exit 141' PIPE
trap 'stop_all; exit 129' HUP
trap 'stop_all' EXIT

if ((DO_LOG)); then
  if ((LCM_LOGGER)); then
    # lcm-logger 1.3.1: '-l URL' is rejected, use --lcm-url=URL. It drops
    # bursts when descheduled (30-message queue): docs/operations.md.
    start logger lcm-logger --lcm-url="$URL" -f "$LOG"
  else
    # A 4 MB socket buffer (capped by net.core.rmem_max): the logger takes
    # every message of the bus and must survive being descheduled.
    if [[ $URL == *\?* ]]; then LOG_URL="$URL&recv_buf_size=4194304"; else LOG_URL="$URL?recv_buf_size=4194304"; fi
    start logger "$LOGGER" --lcm-url="$LOG_URL" -f "$LOG"
  fi
  echo "   recording:  $LOG"
fi
if ((SPY)); then
  # lcm-spy is a window: without a display it would die at once, its reason
  # only in its log. Over ssh (--hosts) the observer host's display counts.
  read -ra SPY_PREFIX <<<"$(on_host lcm-spy)"
  if [[ -z ${DISPLAY:-} && ${SPY_PREFIX[0]:-} != ssh ]]; then
    echo "launch: warning: --spy needs a display and DISPLAY is not set: lcm-spy not started" \
      "(headless: xvfb-run tools/lcm-spy --lcm-url='$URL', or lcm-spy on a machine with a" \
      "display on the same network; docs/operations.md)" >&2
  else
    start lcm-spy "$ROOT/tools/lcm-spy" --lcm-url="$URL"
  fi
fi
if ((VIEWER)); then
  # Normal scheduling, and off the loop's CPU when it has one: it only
  # watches the bus.
  VIEWER_ARGS=("${COMMON[@]}")
  [[ -z $VIEWER_PORT ]] || VIEWER_ARGS+=(--port "$VIEWER_PORT")
  VIEWER_PIN=()
  if [[ $LOOP_CPU != none ]]; then
    OTHER_CPUS=$(seq 0 $(($(nproc) - 1)) | grep -vx "$LOOP_CPU" | paste -sd, -)
    [[ -z $OTHER_CPUS ]] || VIEWER_PIN=(taskset -c "$OTHER_CPUS")
  fi
  start viewer "${VIEWER_PIN[@]}" "$(bin stewart_viewer)" "${VIEWER_ARGS[@]}"
  VIEWER_PID=${PIDS[-1]}
  echo "   viewer:     http://127.0.0.1:${VIEWER_PORT:-<viewer.port, 8080>}/ (viewer.log)"
fi

SAFETY_ARGS=("${COMMON[@]}")
[[ -z $VARIANT ]] || SAFETY_ARGS+=(--variant "$VARIANT")
start safety "${LOOP[@]}" "$SAFETY" "${SAFETY_ARGS[@]}"
start controller "${LOOP[@]}" "$CONTROLLER" "${COMMON[@]}" --scenario "$SCENARIO"
start estimator "${LOOP[@]}" "$ESTIMATOR" "${COMMON[@]}"
WAIT_FOR=("$MONITOR" "${COMMON[@]}" --wait-for safety,controller,estimator --timeout 15)
read -ra MONITOR_PREFIX <<<"$(on_host monitor)"
[[ ${MONITOR_PREFIX[0]:-} != ssh ]] || WAIT_FOR=("$(printf '%q ' "${WAIT_FOR[@]}")")
"${MONITOR_PREFIX[@]}" "${WAIT_FOR[@]}" ||
  { echo "launch: the stack did not come up" >&2; for n in safety controller estimator; do tail -n 5 "$OUT/$n.log" >&2; done; stop_all; exit 1; }

# Only the plant reads the truth: the stack keeps the config's model.
PLANT_ARGS=()
[[ -z $TRUTH ]] || PLANT_ARGS+=(--truth "$TRUTH")
if [[ $PLANT == sim ]]; then
  [[ -z $SEED ]] || PLANT_ARGS+=(--seed "$SEED")
  start plant_sim "${LOOP[@]}" "$PLANT_SIM" "${COMMON[@]}" "${PLANT_ARGS[@]}" --mode "$MODE" --duration "$DURATION"
  PLANT_NAME=plant_sim
else
  # The emulator publishes its ground truth (evaluation only) on the run's URL.
  if ((EMULATOR)); then start hw_emulator "${RT[@]}" "$(bin hw_emulator)" "${COMMON[@]}" "${PLANT_ARGS[@]}"; fi
  start hw_bridge "${LOOP[@]}" "$(bin hw_bridge)" "${COMMON[@]}"
  PLANT_NAME=hw_bridge
fi
start monitor "$MONITOR" "${COMMON[@]}" --progress-of "$DURATION"
MONITOR_LOG="$OUT/monitor.log"

# Wait for the plant to finish the scenario; fail fast if anything dies.
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.3f", b - a }'; }
T0=$(now)
# CPU time the hypervisor gave to others while we ran (the 8th field of the
# cpu line, in USER_HZ ticks): on a virtual machine this, not our code, is
# what usually explains a real-time hiccup.
steal_ticks() { awk '/^cpu /{ print $9; exit }' /proc/stat 2>/dev/null || echo 0; }
STEAL0=$(steal_ticks)
LOAD0=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo "?")
LAST_PROGRESS=""
declare -A OPTIONAL_GONE=()
while :; do
  for i in "${!PIDS[@]}"; do
    name=${NAMES[$i]} pid=${PIDS[$i]}
    if ! kill -0 "$pid" 2>/dev/null; then
      status=0; wait "$pid" || status=$?
      if [[ $name == "$PLANT_NAME" && $status -eq 0 ]]; then break 2; fi
      if [[ $name == monitor || $name == lcm-spy || $name == viewer ]]; then
        # Optional: the run goes on, but the user is told once.
        if [[ -z ${OPTIONAL_GONE[$name]:-} ]]; then
          OPTIONAL_GONE[$name]=1
          echo "launch: warning: $name exited ($status); the run goes on without it: $(tail -n 1 "$OUT/$name.log" 2>/dev/null)" >&2
        fi
        continue
      fi
      fail "$name"
    fi
  done
  if [[ $PLANT == hw ]] && awk -v e="$(elapsed "$T0")" -v d="$DURATION" 'BEGIN { exit !(e > d + 1) }'; then
    break
  fi
  line=$(tail -n 1 "$MONITOR_LOG" 2>/dev/null || true)
  if [[ -n $line && $line != "$LAST_PROGRESS" ]]; then echo "$line"; LAST_PROGRESS=$line; fi
  sleep 0.1  # the wall time below is good to 0.1 s; plant_sim.log has its own, exact
done
WALL=$(elapsed "$T0")
sleep 0.5  # let the logger flush the last messages
# The viewer's CPU time over the run (utime + stime of /proc/<pid>/stat).
VIEWER_CPU=""
if ((VIEWER)) && [[ -r /proc/$VIEWER_PID/stat ]]; then
  VIEWER_CPU=$(awk -v hz="$(getconf CLK_TCK)" '{ sub(/^.*\) /, ""); printf "%.2f", ($12 + $13) / hz }' "/proc/$VIEWER_PID/stat")
fi
stop_all
trap - INT TERM PIPE HUP
printf "== done: %s s simulated in %.1f s wall ==\n" "$DURATION" "$WALL"
{
  echo "wall_time_s: $WALL"
  echo "load_average_at_start: $LOAD0"
  [[ -z $VIEWER_CPU ]] || echo "viewer_cpu_s: $VIEWER_CPU"
  echo "cpu_steal_s: $(awk -v a="$STEAL0" -v b="$(steal_ticks)" -v hz="$(getconf CLK_TCK)" 'BEGIN { printf "%.2f", (b - a) / hz }')"
} >> "$OUT/run.yaml"

# Whether the log holds every message the stack published (each numbers
# its own): lcm-logger drops bursts when descheduled (docs/operations.md,
# "Logging"), and a number computed from an incomplete log is short.
if ((DO_LOG)); then
  CHECK=$(find "$BUILD" -maxdepth 3 -type f -name stewart_log_export -perm -u+x -print -quit)
  if [[ -z $CHECK ]]; then
    echo "launch: stewart_log_export is not built: the log's completeness is not checked" >&2
  elif [[ ! -f $LOG ]]; then
    echo "launch: WARNING: no log at $LOG (see $OUT/logger.log)" >&2
  else
    COMPLETENESS=$("$CHECK" "$LOG" --check 2>&1) || true
    if [[ $COMPLETENESS == *WARNING* ]]; then
      echo "launch: $COMPLETENESS" >&2
      ((LCM_LOGGER)) && echo "launch: recorded with --lcm-logger, which drops bursts of messages; the default stewart_logger does not" >&2
    else
      echo "   $COMPLETENESS"
    fi
  fi
fi
if ((DO_REPORT)); then
  "$ROOT/tools/report.sh" "$OUT" "$LOG"
fi
