#pragma once

#include <optional>

namespace stewart::safety {

/// An infeasible force-limited step relaxes the velocity condition by the
/// least amount the position condition and the force limits allow, found by
/// bisection to this fraction of the shortfall of the answer without it, in
/// at most kMaxRelaxationSteps QP solves (LeastRelaxation; docs/safety.md,
/// "The least relaxation of the velocity row").
constexpr double kRelaxationRelTol = 1e-3;
constexpr int kMaxRelaxationSteps = 12;

/// The least relaxation r in (0, upper) for which `solves(r)` returns true,
/// by bisection to kRelaxationRelTol * upper in at most kMaxRelaxationSteps
/// calls. `upper` (> 0) is known to solve: the caller's answer without the
/// relaxed rows misses them by that much. `solves` must be monotone (a
/// larger relaxation only enlarges the feasible set) and keeps the answer of
/// its last successful call. nullopt when no try below `upper` solved: the
/// caller's answer without the rows stands.
template <typename Solves>
std::optional<double> LeastRelaxation(double upper, Solves&& solves) {
  double feasible = upper;
  double infeasible = 0.0;
  bool improved = false;
  for (int i = 0; i < kMaxRelaxationSteps && feasible - infeasible > kRelaxationRelTol * upper;
       ++i) {
    const double relaxation = 0.5 * (feasible + infeasible);
    if (solves(relaxation)) {
      feasible = relaxation;
      improved = true;
    } else {
      infeasible = relaxation;
    }
  }
  if (!improved) return std::nullopt;
  return feasible;
}

}  // namespace stewart::safety
