#include "stewart/safety/clp_reference_qp.h"

#include <ClpSimplex.hpp>
#include <CoinPackedMatrix.hpp>
#include <array>

namespace stewart::safety {

ProjectionStatus ClpReferenceQp::Solve(const ProjectionQp& qp, Vector6d* x) {
  // Solved for d = x - x0: min 1/2 d^T d  s.t.  a_i^T d >= b_i - a_i^T x0. Clp's
  // tolerances are absolute, so the unshifted problem (|x0| up to ~1e3 in the
  // acceleration metric's coordinates) loses digits; the shift keeps its
  // answer at zero when nothing is active.
  std::array<double, 6> objective{}, col_lower{}, col_upper{};
  for (int i = 0; i < 6; ++i) {
    objective[static_cast<size_t>(i)] = 0.0;
    col_lower[static_cast<size_t>(i)] = -COIN_DBL_MAX;
    col_upper[static_cast<size_t>(i)] = COIN_DBL_MAX;
  }
  CoinPackedMatrix matrix(false, 0, 0);
  matrix.setDimensions(0, 6);
  std::array<double, kMaxQpRows> row_lower{}, row_upper{};
  const std::array<int, 6> index = {0, 1, 2, 3, 4, 5};
  for (int r = 0; r < qp.m; ++r) {
    // Unit-norm rows: Clp's feasibility tolerance is absolute.
    const double norm = qp.a.row(r).norm();
    if (!(norm > 0.0)) return ProjectionStatus::kIterationLimit;
    std::array<double, 6> row{};
    for (int i = 0; i < 6; ++i) row[static_cast<size_t>(i)] = qp.a(r, i) / norm;
    matrix.appendRow(6, index.data(), row.data());
    row_lower[static_cast<size_t>(r)] = (qp.b(r) - qp.a.row(r).dot(qp.x0)) / norm;
    row_upper[static_cast<size_t>(r)] = COIN_DBL_MAX;
  }
  ClpSimplex model;
  model.setLogLevel(0);
  model.loadProblem(matrix, col_lower.data(), col_upper.data(), objective.data(), row_lower.data(),
                    row_upper.data());
  const std::array<CoinBigIndex, 7> start = {0, 1, 2, 3, 4, 5, 6};
  const std::array<double, 6> diagonal = {1, 1, 1, 1, 1, 1};
  model.loadQuadraticObjective(6, start.data(), index.data(), diagonal.data());
  model.scaling(0);
  model.setPrimalTolerance(1e-12);
  model.setDualTolerance(1e-12);
  model.primal();
  if (model.isProvenPrimalInfeasible()) return ProjectionStatus::kInfeasible;
  if (!model.isProvenOptimal()) return ProjectionStatus::kIterationLimit;
  const double* solution = model.primalColumnSolution();
  for (int i = 0; i < 6; ++i) (*x)(i) = qp.x0(i) + solution[i];
  return ProjectionStatus::kOptimal;
}

}  // namespace stewart::safety
