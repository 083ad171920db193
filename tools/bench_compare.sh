#!/usr/bin/env bash
# Runs the benchmarks of two Release builds back to back, for a before/after
# comparison in one session (docs/performance.md): each benchmark of BEFORE,
# then of AFTER, then the safety filter's core and full step alternated three
# times.
#   tools/bench_compare.sh BEFORE_BUILD_DIR AFTER_BUILD_DIR
set -euo pipefail
[[ $# -eq 2 ]] || { echo "usage: tools/bench_compare.sh BEFORE_BUILD_DIR AFTER_BUILD_DIR" >&2; exit 2; }
for side in "$1" "$2"; do
  echo "=== $side model"
  "$side/model/model_bench" --benchmark_min_time=0.2 \
    --benchmark_filter='EvaluateDynamics|ForwardDynamics|InverseDynamics' | grep -E '^BM_'
  echo "=== $side safety"
  "$side/safety/safety_bench" --benchmark_min_time=0.3 \
    --benchmark_filter='BM_ClosedFormCore$|BM_ClosedFormFullStep|BM_UncomposedFullStep|BM_ForceLimitedFullStep' |
    grep -E '^BM_'
  echo "=== $side plant_sim"
  "$side/plant_sim/plant_sim_bench" --benchmark_min_time=0.5 | grep -E '^BM_' | head -4
  echo "=== $side estimator"
  "$side/estimator/estimator_bench" --benchmark_min_time=0.3 | grep -E '^BM_'
  echo "=== $side closed loop"
  /usr/bin/time -f "%e s wall, %M KB peak" "$side/tools/stewart_closed_loop_sim" --duration 40 \
    --scenario paper 2>&1 | tail -1
done
for _ in 1 2 3; do
  for side in "$1" "$2"; do
    echo "=== $side safety (alternated)"
    "$side/safety/safety_bench" --benchmark_min_time=0.3 \
      --benchmark_filter='BM_ClosedFormCore$|BM_ClosedFormFullStep' | grep -E '^BM_'
  done
done
