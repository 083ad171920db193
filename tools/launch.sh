#!/usr/bin/env bash
# The main job. Until every process of the stack exists, it builds what
# exists, evaluates the model on the paper's scenario, and says what is
# still missing.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh >/dev/null
BUILD_DIR=${STEWART_BUILD_DIR:-build}

echo "== Stewart platform stack =="
missing=()
for proc in plant_sim estimator controller safety hw_bridge; do
  bin=$(find "$BUILD_DIR" -maxdepth 3 -type f -name "$proc" -perm -u+x 2>/dev/null | head -n 1)
  if [[ -n "$bin" ]]; then echo "built:   $proc ($bin)"; else echo "missing: $proc"; missing+=("$proc"); fi
done

echo
echo "== model at the paper's setpoints (leg lengths, m; holding forces, N) =="
for q in "0 0 0.4 0 0 0" "0.1 0 0.4 0 0 0" "0 0.1 0.4 0 0 0" "0 0 0.45 0 0 0" "0 0 0.5 0 0 0"; do
  # shellcheck disable=SC2086
  "$BUILD_DIR/tools/stewart_model_tool" --q $q | /usr/bin/python3 -c '
import json, sys
r = json.load(sys.stdin)
fmt = lambda v: " ".join("%7.4f" % x for x in v)
print("q=[%s]  legs [%s]  in stroke: %s  F_hold [%s]" % (fmt(r["q"][:3]), fmt(r["leg_length_m"]),
      r["in_stroke"], fmt(r["inverse_dynamics_F"])))'
done

if ((${#missing[@]})); then
  echo
  echo "The closed-loop stack cannot run yet: missing ${missing[*]}."
  exit 0
fi
