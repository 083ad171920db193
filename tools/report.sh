#!/usr/bin/env bash
# Writes <run>/report.md and plots from a run folder made by tools/launch.sh:
# exports the log to CSV per channel (and how complete it is, from the seq
# numbers of its streams: <run>/log_continuity.json), replays the safety filter offline as
# closed form and as QP reference on the recorded inputs (stewart_replay,
# into <run>/replay/), then tools/plots/report.py.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
usage="usage: tools/report.sh RUN_FOLDER [LOG] (LOG: the run's log, default RUN_FOLDER/log.lcm)"
[[ $# -ge 1 && $# -le 2 ]] || { echo "$usage" >&2; exit 2; }
[[ -d $1 ]] || { echo "report: '$1' is not a run folder (tools/launch.sh --out makes one)" >&2; exit 2; }
RUN=$(realpath "$1")
LOG=$(realpath -m "${2:-$RUN/log.lcm}")
[[ -f $RUN/config.yaml ]] || { echo "report: '$RUN' has no config.yaml: not a run folder of tools/launch.sh" >&2; exit 2; }
[[ -f $LOG ]] || { echo "report: no log '$LOG' (a run started with --no-log has none; one recorded elsewhere: tools/report.sh $RUN FILE)" >&2; exit 2; }
BUILD=${STEWART_BUILD_DIR:-$ROOT/build}
EXPORT=$(find "$BUILD" -maxdepth 3 -type f -name stewart_log_export -perm -u+x -print -quit)
[[ -n $EXPORT ]] || { echo "report: stewart_log_export is not built in $BUILD" >&2; exit 2; }
rm -f "$RUN/log_continuity.json"
if ! "$EXPORT" "$LOG" --out "$RUN/csv" --continuity-json "$RUN/log_continuity.json" \
    >"$RUN/csv_export.txt" 2>&1; then
  echo "report: exporting '$LOG' failed; its output ($RUN/csv_export.txt):" >&2
  tail -n 5 "$RUN/csv_export.txt" >&2
  exit 1
fi

# Closed form vs QP reference on the same recorded inputs (report section
# "Closed form vs QP reference"). A missing tool or a failed replay only
# leaves the section out, with the reason in the report.
REPLAY=$(find "$BUILD" -maxdepth 3 -type f -name stewart_replay -perm -u+x -print -quit || true)
mkdir -p "$RUN/replay"
rm -f "$RUN"/replay/{closed_form,qp}.{json,csv,txt} "$RUN/replay/missing.txt"
if [[ -n $REPLAY ]]; then
  for variant in closed_form qp; do
    status=0
    "$REPLAY" "$RUN" --log "$LOG" --variant "$variant" --json "$RUN/replay/$variant.json" \
      --csv "$RUN/replay/$variant.csv" >"$RUN/replay/$variant.txt" 2>&1 || status=$?
    if ((status != 0)); then
      echo "report: stewart_replay --variant $variant failed (exit $status), see $RUN/replay/$variant.txt" >&2
      rm -f "$RUN/replay/$variant.json"
    fi
  done
else
  echo "stewart_replay is not built in $BUILD" >"$RUN/replay/missing.txt"
  echo "report: stewart_replay is not built in $BUILD: no closed form vs QP section" >&2
fi
/usr/bin/python3 "$ROOT/tools/plots/report.py" "$RUN"
echo "report: $RUN/report.md"
