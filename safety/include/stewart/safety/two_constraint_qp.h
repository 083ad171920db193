#pragma once
// Closed-form solution of the filter's QP (NOTES.md, docs/safety.md):
//
//   min ||F - F_des||^2  s.t.  psi_i + g_i^T (F - F_des) >= 0,  i in {p, v}
//
// F* = F_des + mu_p g_p + mu_v g_v, mu >= 0. The exact KKT case analysis
// tries the cases in order and returns the first whose KKT conditions hold;
// the QP is strictly convex so, when feasible, exactly that one is optimal.
#include <array>
#include <cstdint>

#include "stewart/common/enum_table.h"
#include "stewart/model/types.h"
#include "stewart/safety/projection_qp.h"  // kZeroNormal

namespace stewart::safety {

/// Case taken (values match safety_diagnostics_t.CASE_*).
enum class FilterCase : std::int8_t {
  kNone = 0,        ///< both conditions hold at F_des
  kPosition = 1,    ///< only the position condition active
  kVelocity = 2,    ///< only the velocity condition active
  kBoth = 3,        ///< both active
  kInfeasible = 4,  ///< the QP has no solution (reported by the solver)
  kFallback = 5,    ///< invalid input: the safe stop was applied
};
/// Every case by its value: kFilterCaseNames.entries[i].first == FilterCase(i).
inline constexpr EnumTable<FilterCase, 6> kFilterCaseNames{{{
    {FilterCase::kNone, "none"},
    {FilterCase::kPosition, "position"},
    {FilterCase::kVelocity, "velocity"},
    {FilterCase::kBoth, "both"},
    {FilterCase::kInfeasible, "infeasible"},
    {FilterCase::kFallback, "fallback"},
}}};
/// Counts per case, indexed by the case's value.
using FilterCaseCounts = std::array<long, kFilterCaseNames.size()>;

/// The two affine conditions. An absent group (no constraint configured) is
/// never active.
struct TwoConstraintProblem {
  double psi_p = 0.0, psi_v = 0.0;
  Vector6d g_p = Vector6d::Zero(), g_v = Vector6d::Zero();
  bool has_p = false, has_v = false;
};

/// The same problem by its Gram matrix: the case analysis needs the normals
/// only through their dot products, and the filter gets these in the
/// acceleration metric without forming the normals (docs/safety.md).
struct TwoConstraintGram {
  double psi_p = 0.0, psi_v = 0.0;
  double pp = 0.0, vv = 0.0, pv = 0.0;  ///< g_p.g_p, g_v.g_v, g_p.g_v
  bool has_p = false, has_v = false;
};

/// psi, the dot products of g_p, g_v and has_* of `problem`.
TwoConstraintGram GramOf(const TwoConstraintProblem& problem);

struct TwoConstraintSolution {
  double mu_p = 0.0, mu_v = 0.0;
  FilterCase filter_case = FilterCase::kNone;
  bool feasible = true;
};

/// Gram determinant below this fraction of |g_p|^2 |g_v|^2 (sin^2 of the
/// angle between the normals) counts as parallel normals.
constexpr double kParallelSin2 = 1e-12;

/// Opposing normals (g_p.g_v < 0) count as anti-parallel below this sin^2,
/// a wider band than kParallelSin2. Both conditions active with opposing
/// normals at angle pi - a meet only at the far tip of a wedge: the exact
/// correction is up to sqrt(2) (|psi_p|/|g_p| + |psi_v|/|g_v|) / sin a, 1e6 times
/// either condition's own correction at sin^2 = 1e-12 (measured: 6.6e6 N on
/// the filter). Below this threshold case 4 is not taken: the slab is
/// treated as empty (case 5, the flagged infeasibility fallback), which
/// bounds every correction the case analysis returns by 1415 times the
/// conditions' own (docs/safety.md, "Exact case analysis"). Same-direction
/// normals keep kParallelSin2: their case-4 correction stays within the
/// conditions' own whatever the angle.
constexpr double kOpposingParallelSin2 = 1e-6;

/// Exact KKT case analysis (cases 1-5 of NOTES.md).
TwoConstraintSolution SolveExactKkt(const TwoConstraintProblem& problem);
TwoConstraintSolution SolveExactKkt(const TwoConstraintGram& gram);

/// The paper's literal Theorem 1: the case is chosen by the signs of psi_p,
/// psi_v at F_des alone, and its formula applied without the validity check.
/// Not the QP solution in general (NOTES.md); kept to show the difference.
/// Degenerate normals still give a defined (infeasible) answer.
TwoConstraintSolution SolvePaperRule(const TwoConstraintProblem& problem);
TwoConstraintSolution SolvePaperRule(const TwoConstraintGram& gram);

/// Lexicographic fallback for an infeasible problem: satisfy the position
/// condition with the least correction (relaxing the velocity one), else the
/// velocity condition alone; `feasible` stays false.
TwoConstraintSolution SolveInfeasibleFallback(const TwoConstraintProblem& problem);
TwoConstraintSolution SolveInfeasibleFallback(const TwoConstraintGram& gram);

}  // namespace stewart::safety
