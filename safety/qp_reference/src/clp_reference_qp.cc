#include "stewart/safety/clp_reference_qp.h"

#include <ClpSimplex.hpp>
#include <CoinPackedMatrix.hpp>
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

namespace stewart::safety {
namespace {

// The QP in Clp's coordinates: d = x - x0, unit rows n_r^T d >= c_r. Clp's
// tolerances are absolute, so the unshifted problem (|x0| up to ~1e3 in the
// acceleration metric's coordinates) and unnormalized rows lose digits.
template <int MaxRows>
struct ShiftedQp {
  int m = 0;
  Eigen::Matrix<double, MaxRows, 6> n;
  Eigen::Matrix<double, MaxRows, 1> c;
};

// A slack below this (times the problem's scale) puts a row in the active
// set read off the interior point: the barrier stops ~1e-8 from the bounds.
constexpr double kBarrierActiveSlack = 1e-6;
// KKT certificate, relative to the problem's scale: rows violated by no more,
// multipliers no more negative.
constexpr double kCertificateTol = 1e-11;
// Interior-point iterations before the barrier gives up (it takes ~10-40).
constexpr int kMaxBarrierIterations = 200;

template <int MaxRows>
double Scale(const ShiftedQp<MaxRows>& qp, const Vector6d& d) {
  double scale = std::max(1.0, d.norm());
  for (int r = 0; r < qp.m; ++r) scale = std::max(scale, std::abs(qp.c(r)));
  return scale;
}

// The least-norm d on the rows of `active` as equalities, with its
// multipliers (d = sum lambda_r n_r). Rows with the same unit normal are one
// row (the more restrictive), so the active normals stay independent unless
// the set is degenerate, which the certificate then rejects.
template <int MaxRows>
struct Polished {
  Vector6d d = Vector6d::Zero();
  Eigen::Matrix<double, MaxRows, 1> lambda = Eigen::Matrix<double, MaxRows, 1>::Zero();
  bool solved = false;
};

template <int MaxRows>
Polished<MaxRows> PolishOnActiveSet(const ShiftedQp<MaxRows>& qp,
                                    const std::array<bool, MaxRows>& active) {
  Polished<MaxRows> out;
  std::array<int, MaxRows> rows{};
  int k = 0;
  for (int r = 0; r < qp.m; ++r) {
    if (!active[static_cast<size_t>(r)]) continue;
    bool duplicate = false;
    for (int j = 0; j < k; ++j) {
      const int s = rows[static_cast<size_t>(j)];
      if ((qp.n.row(s) - qp.n.row(r)).norm() < 1e-12) {
        if (qp.c(r) > qp.c(s)) rows[static_cast<size_t>(j)] = r;
        duplicate = true;
        break;
      }
    }
    if (!duplicate) rows[static_cast<size_t>(k++)] = r;
  }
  if (k > 6) return out;
  if (k == 0) {
    out.solved = true;
    return out;
  }
  Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6> n_s(k, 6);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> c_s(k);
  for (int j = 0; j < k; ++j) {
    n_s.row(j) = qp.n.row(rows[static_cast<size_t>(j)]);
    c_s(j) = qp.c(rows[static_cast<size_t>(j)]);
  }
  // d = N^T lambda with N N^T lambda = c: the projection of 0 on the
  // active rows' affine set.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6> gram = n_s * n_s.transpose();
  const Eigen::FullPivLU<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>> lu(gram);
  if (lu.rank() < k) return out;
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1> lambda_s = lu.solve(c_s);
  out.d = n_s.transpose() * lambda_s;
  for (int j = 0; j < k; ++j) out.lambda(rows[static_cast<size_t>(j)]) = lambda_s(j);
  out.solved = out.d.allFinite();
  return out;
}

template <int MaxRows>
ProjectionStatus SolveWithClp(const ProjectionQpN<MaxRows>& qp, Vector6d* x) {
  ShiftedQp<MaxRows> shifted;
  shifted.m = qp.m;
  for (int r = 0; r < qp.m; ++r) {
    const double norm = qp.a.row(r).norm();
    if (!(norm > 0.0)) return ProjectionStatus::kIterationLimit;
    shifted.n.row(r) = qp.a.row(r) / norm;
    shifted.c(r) = (qp.b(r) - qp.a.row(r).dot(qp.x0)) / norm;
  }

  // Clp's interior point (barrier) finds the active set. Its simplex for QPs
  // (primal(), tolerances 1e-12) was exact where it finished, but with these
  // free columns it cycled without end on some states (two barrier rows
  // active, the force rows far away: > 10 min on one 6-variable QP, deaf to
  // its iteration and time limits; boxed columns made it call feasible QPs
  // infeasible instead). The barrier's iterations are bounded.
  std::array<double, 6> objective{}, col_lower{}, col_upper{};
  col_lower.fill(-COIN_DBL_MAX);
  col_upper.fill(COIN_DBL_MAX);
  CoinPackedMatrix matrix(false, 0, 0);
  matrix.setDimensions(0, 6);
  std::array<double, MaxRows> row_lower{}, row_upper{};
  const std::array<int, 6> index = {0, 1, 2, 3, 4, 5};
  for (int r = 0; r < qp.m; ++r) {
    std::array<double, 6> row{};
    for (int i = 0; i < 6; ++i) row[static_cast<size_t>(i)] = shifted.n(r, i);
    matrix.appendRow(6, index.data(), row.data());
    row_lower[static_cast<size_t>(r)] = shifted.c(r);
    row_upper[static_cast<size_t>(r)] = COIN_DBL_MAX;
  }
  const auto load_rows = [&](ClpSimplex* model) {
    model->setLogLevel(0);
    model->loadProblem(matrix, col_lower.data(), col_upper.data(), objective.data(),
                       row_lower.data(), row_upper.data());
    model->scaling(0);
  };
  // Without a certified answer, the verdict is the LP's: Clp's dual simplex
  // on the rows alone (no objective) proves an empty set, where the barrier
  // only stops without converging.
  const auto verdict_without_answer = [&load_rows]() {
    ClpSimplex lp;
    load_rows(&lp);
    lp.dual();
    return lp.isProvenPrimalInfeasible() ? ProjectionStatus::kInfeasible
                                         : ProjectionStatus::kIterationLimit;
  };
  ClpSimplex qp_model;
  load_rows(&qp_model);
  const std::array<CoinBigIndex, 7> start = {0, 1, 2, 3, 4, 5, 6};
  const std::array<double, 6> diagonal = {1, 1, 1, 1, 1, 1};
  qp_model.loadQuadraticObjective(6, start.data(), index.data(), diagonal.data());
  // ClpSimplex::barrier directly, without crossover: through initialSolve
  // some un-composed QPs left a status that trips an assertion there (an
  // abort). Below 1000 the iteration limit is the barrier's own. Its status
  // is not read: it called ~1.5 % of the un-composed sweeps' QPs not optimal
  // whose point the certificate below then proved; what counts is whether
  // its point leads to a certified answer.
  qp_model.setMaximumIterations(kMaxBarrierIterations);
  qp_model.barrier(false);
  if (qp_model.primalColumnSolution() == nullptr) return verdict_without_answer();

  // The answer is the exact projection on that active set, certified by the
  // KKT conditions (feasible, multipliers >= 0: sufficient for this convex
  // QP), so its digits do not depend on where the barrier stopped. Where the
  // barrier's set is off by a nearly active row, the most violated row joins
  // or the most negative multiplier leaves until the certificate holds.
  Vector6d d_barrier;
  for (int i = 0; i < 6; ++i) d_barrier(i) = qp_model.primalColumnSolution()[i];
  const double barrier_scale = Scale(shifted, d_barrier);
  std::array<bool, MaxRows> active{};
  for (int r = 0; r < qp.m; ++r) {
    active[static_cast<size_t>(r)] =
        shifted.n.row(r).dot(d_barrier) - shifted.c(r) <= kBarrierActiveSlack * barrier_scale;
  }
  for (int attempt = 0; attempt <= 2 * qp.m; ++attempt) {
    const Polished<MaxRows> polished = PolishOnActiveSet<MaxRows>(shifted, active);
    if (!polished.solved) return verdict_without_answer();
    const double scale = Scale(shifted, polished.d);
    int most_violated = -1;
    double worst_violation = kCertificateTol * scale;
    int most_negative = -1;
    double worst_multiplier =
        -kCertificateTol * std::max(1.0, polished.lambda.cwiseAbs().maxCoeff());
    for (int r = 0; r < qp.m; ++r) {
      const double violation = shifted.c(r) - shifted.n.row(r).dot(polished.d);
      if (violation > worst_violation) {
        worst_violation = violation;
        most_violated = r;
      }
      if (polished.lambda(r) < worst_multiplier) {
        worst_multiplier = polished.lambda(r);
        most_negative = r;
      }
    }
    if (most_violated < 0 && most_negative < 0) {
      *x = qp.x0 + polished.d;
      return ProjectionStatus::kOptimal;
    }
    if (most_negative >= 0) {
      active[static_cast<size_t>(most_negative)] = false;
    } else {
      active[static_cast<size_t>(most_violated)] = true;
    }
  }
  return verdict_without_answer();
}

}  // namespace

ProjectionStatus ClpReferenceQp::Solve(const ProjectionQp& qp, Vector6d* x) {
  return SolveWithClp(qp, x);
}

ProjectionStatus ClpReferenceQp::Solve(const UncomposedQp& qp, Vector6d* x) {
  return SolveWithClp(qp, x);
}

}  // namespace stewart::safety
