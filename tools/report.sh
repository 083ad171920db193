#!/usr/bin/env bash
# Writes <run>/report.md and plots from a run folder made by tools/launch.sh:
# exports the log to CSV per channel, replays the safety filter offline as
# closed form and as QP reference on the recorded inputs (stewart_replay,
# into <run>/replay/), then tools/plots/report.py.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
RUN=$(realpath "${1:?usage: tools/report.sh RUN_FOLDER}")
BUILD=${STEWART_BUILD_DIR:-$ROOT/build}
EXPORT=$(find "$BUILD" -maxdepth 3 -type f -name stewart_log_export -perm -u+x -print -quit)
"$EXPORT" "$RUN/log.lcm" --out "$RUN/csv" >/dev/null 2>&1

# Closed form vs QP reference on the same recorded inputs (report section
# "Closed form vs QP reference"). A missing tool or a failed replay only
# leaves the section out, with the reason in the report.
REPLAY=$(find "$BUILD" -maxdepth 3 -type f -name stewart_replay -perm -u+x -print -quit || true)
mkdir -p "$RUN/replay"
rm -f "$RUN"/replay/{closed_form,qp}.{json,csv,txt} "$RUN/replay/missing.txt"
if [[ -n $REPLAY ]]; then
  for variant in closed_form qp; do
    status=0
    "$REPLAY" "$RUN" --variant "$variant" --json "$RUN/replay/$variant.json" \
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
