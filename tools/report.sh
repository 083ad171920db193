#!/usr/bin/env bash
# Writes <run>/report.md and plots from a run folder made by tools/launch.sh:
# exports the log to CSV per channel, then tools/plots/report.py.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
RUN=$(realpath "${1:?usage: tools/report.sh RUN_FOLDER}")
BUILD=${STEWART_BUILD_DIR:-$ROOT/build}
EXPORT=$(find "$BUILD" -maxdepth 3 -type f -name stewart_log_export -perm -u+x -print -quit)
"$EXPORT" "$RUN/log.lcm" --out "$RUN/csv" >/dev/null 2>&1
/usr/bin/python3 "$ROOT/tools/plots/report.py" "$RUN"
echo "report: $RUN/report.md"
