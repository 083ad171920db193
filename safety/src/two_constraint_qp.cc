#include "stewart/safety/two_constraint_qp.h"

#include <cmath>

namespace stewart::safety {
namespace {

// Relative slack for the validity checks "x >= 0": x is a sum of terms whose
// rounding error is ~1e-16 of their magnitude.
constexpr double kRelTol = 1e-12;

bool NonNegative(double value, double scale) { return value >= -kRelTol * scale; }

struct Gram {
  double pp, vv, pv;
  bool p_zero, v_zero;
};

Gram MakeGram(const TwoConstraintGram& pr) {
  Gram g{pr.pp, pr.vv, pr.pv, false, false};
  g.p_zero = !pr.has_p || !(g.pp > kZeroNormal * kZeroNormal);
  g.v_zero = !pr.has_v || !(g.vv > kZeroNormal * kZeroNormal);
  // An absent group has no normal: the other's correction cannot move it.
  if (!pr.has_p || !pr.has_v) g.pv = 0.0;
  return g;
}

// Absent groups are satisfied by definition.
double PsiP(const TwoConstraintGram& pr) { return pr.has_p ? pr.psi_p : 0.0; }
double PsiV(const TwoConstraintGram& pr) { return pr.has_v ? pr.psi_v : 0.0; }

TwoConstraintSolution Make(double mu_p, double mu_v, FilterCase c, bool feasible = true) {
  return {mu_p, mu_v, c, feasible};
}

}  // namespace

TwoConstraintGram GramOf(const TwoConstraintProblem& pr) {
  TwoConstraintGram g;
  g.psi_p = pr.psi_p;
  g.psi_v = pr.psi_v;
  g.pp = pr.g_p.squaredNorm();
  g.vv = pr.g_v.squaredNorm();
  g.pv = pr.g_p.dot(pr.g_v);
  g.has_p = pr.has_p;
  g.has_v = pr.has_v;
  return g;
}

TwoConstraintSolution SolveExactKkt(const TwoConstraintProblem& pr) {
  return SolveExactKkt(GramOf(pr));
}
TwoConstraintSolution SolvePaperRule(const TwoConstraintProblem& pr) {
  return SolvePaperRule(GramOf(pr));
}
TwoConstraintSolution SolveInfeasibleFallback(const TwoConstraintProblem& pr) {
  return SolveInfeasibleFallback(GramOf(pr));
}

TwoConstraintSolution SolveExactKkt(const TwoConstraintGram& pr) {
  const double psi_p = PsiP(pr), psi_v = PsiV(pr);
  // Case 1: F_des itself is feasible.
  if (psi_p >= 0.0 && psi_v >= 0.0) return Make(0, 0, FilterCase::kNone);
  const Gram g = MakeGram(pr);
  // Case 2: only p active. Valid iff the correction keeps v satisfied.
  if (!g.p_zero && psi_p < 0.0) {
    const double mu_p = -psi_p / g.pp;
    const double psi_v_after = psi_v + mu_p * g.pv;
    if (NonNegative(psi_v_after, std::fabs(psi_v) + std::fabs(mu_p * g.pv))) {
      return Make(mu_p, 0, FilterCase::kPosition);
    }
  }
  // Case 3: only v active.
  if (!g.v_zero && psi_v < 0.0) {
    const double mu_v = -psi_v / g.vv;
    const double psi_p_after = psi_p + mu_v * g.pv;
    if (NonNegative(psi_p_after, std::fabs(psi_p) + std::fabs(mu_v * g.pv))) {
      return Make(0, mu_v, FilterCase::kVelocity);
    }
  }
  // Case 4: both active; needs linearly independent normals.
  if (!g.p_zero && !g.v_zero) {
    const double det = g.pp * g.vv - g.pv * g.pv;
    const double parallel_sin2 = g.pv < 0.0 ? kOpposingParallelSin2 : kParallelSin2;
    if (det > parallel_sin2 * g.pp * g.vv) {
      const double mu_p = (-psi_p * g.vv + psi_v * g.pv) / det;
      const double mu_v = (-psi_v * g.pp + psi_p * g.pv) / det;
      const double scale_p = (std::fabs(psi_p * g.vv) + std::fabs(psi_v * g.pv)) / det;
      const double scale_v = (std::fabs(psi_v * g.pp) + std::fabs(psi_p * g.pv)) / det;
      if (NonNegative(mu_p, scale_p) && NonNegative(mu_v, scale_v)) {
        return Make(std::fmax(mu_p, 0.0), std::fmax(mu_v, 0.0), FilterCase::kBoth);
      }
    }
  }
  // Case 5: a violated condition with a zero normal, or (anti)parallel
  // normals with an empty slab (opposing normals within kOpposingParallelSin2
  // count as anti-parallel).
  return Make(0, 0, FilterCase::kInfeasible, false);
}

TwoConstraintSolution SolvePaperRule(const TwoConstraintGram& pr) {
  const double psi_p = PsiP(pr), psi_v = PsiV(pr);
  const Gram g = MakeGram(pr);
  if (psi_p >= 0.0 && psi_v >= 0.0) return Make(0, 0, FilterCase::kNone);
  if (psi_p < 0.0 && psi_v >= 0.0) {
    if (g.p_zero) return Make(0, 0, FilterCase::kInfeasible, false);
    return Make(-psi_p / g.pp, 0, FilterCase::kPosition);
  }
  if (psi_v < 0.0 && psi_p >= 0.0) {
    if (g.v_zero) return Make(0, 0, FilterCase::kInfeasible, false);
    return Make(0, -psi_v / g.vv, FilterCase::kVelocity);
  }
  const double det = g.pp * g.vv - g.pv * g.pv;
  if (g.p_zero || g.v_zero || !(det > kParallelSin2 * g.pp * g.vv)) {
    return Make(0, 0, FilterCase::kInfeasible, false);
  }
  // Both violated: solve with both active, whatever the sign of mu.
  return Make((-psi_p * g.vv + psi_v * g.pv) / det, (-psi_v * g.pp + psi_p * g.pv) / det,
              FilterCase::kBoth);
}

TwoConstraintSolution SolveInfeasibleFallback(const TwoConstraintGram& pr) {
  const double psi_p = PsiP(pr), psi_v = PsiV(pr);
  const Gram g = MakeGram(pr);
  // Position first: on the slab of (anti)parallel normals, the point of the
  // position boundary closest to F_des is also where the velocity violation
  // is least, so this is the least relaxation of the velocity condition.
  if (psi_p >= 0.0) {
    // F_des keeps position: move toward velocity only as far as position
    // allows (anti-parallel normals, pv < 0), the least velocity relaxation.
    double mu_v = 0.0;
    if (!g.v_zero && psi_v < 0.0) {
      mu_v = -psi_v / g.vv;
      if (g.pv < 0.0) mu_v = std::fmin(mu_v, psi_p / -g.pv);
    }
    return Make(0, mu_v, FilterCase::kInfeasible, false);
  }
  if (!g.p_zero) return Make(-psi_p / g.pp, 0, FilterCase::kInfeasible, false);
  // The force cannot change Psi_p (at rest): do the best for velocity.
  if (!g.v_zero && psi_v < 0.0) return Make(0, -psi_v / g.vv, FilterCase::kInfeasible, false);
  return Make(0, 0, FilterCase::kInfeasible, false);
}

}  // namespace stewart::safety
