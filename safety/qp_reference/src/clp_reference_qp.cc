#include "stewart/safety/clp_reference_qp.h"

#include <ClpSimplex.hpp>
#include <CoinPackedMatrix.hpp>
#include <array>

namespace stewart::safety {

ProjectionStatus ClpReferenceQp::Solve(const ProjectionQp& qp, Vector6d* x) {
  // min 1/2 F^T F - x0^T F  (same minimiser as ||F - x0||^2).
  std::array<double, 6> objective{}, col_lower{}, col_upper{};
  for (int i = 0; i < 6; ++i) {
    objective[static_cast<size_t>(i)] = -qp.x0(i);
    col_lower[static_cast<size_t>(i)] = -COIN_DBL_MAX;
    col_upper[static_cast<size_t>(i)] = COIN_DBL_MAX;
  }
  CoinPackedMatrix matrix(false, 0, 0);
  matrix.setDimensions(0, 6);
  std::array<double, kMaxQpRows> row_lower{}, row_upper{};
  const std::array<int, 6> index = {0, 1, 2, 3, 4, 5};
  for (int r = 0; r < qp.m; ++r) {
    std::array<double, 6> row{};
    for (int i = 0; i < 6; ++i) row[static_cast<size_t>(i)] = qp.a(r, i);
    matrix.appendRow(6, index.data(), row.data());
    row_lower[static_cast<size_t>(r)] = qp.b(r);
    row_upper[static_cast<size_t>(r)] = COIN_DBL_MAX;
  }
  ClpSimplex model;
  model.setLogLevel(0);
  model.loadProblem(matrix, col_lower.data(), col_upper.data(), objective.data(), row_lower.data(),
                    row_upper.data());
  const std::array<CoinBigIndex, 7> start = {0, 1, 2, 3, 4, 5, 6};
  const std::array<double, 6> diagonal = {1, 1, 1, 1, 1, 1};
  model.loadQuadraticObjective(6, start.data(), index.data(), diagonal.data());
  model.setPrimalTolerance(1e-10);
  model.setDualTolerance(1e-10);
  model.primal();
  if (model.isProvenPrimalInfeasible()) return ProjectionStatus::kInfeasible;
  if (!model.isProvenOptimal()) return ProjectionStatus::kIterationLimit;
  const double* solution = model.primalColumnSolution();
  for (int i = 0; i < 6; ++i) (*x)(i) = solution[i];
  return ProjectionStatus::kOptimal;
}

}  // namespace stewart::safety
