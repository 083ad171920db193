// GPL-2+ component (ALGLIB): see alglib_reference_qp.h.
#include "stewart/safety/alglib_reference_qp.h"

#include <libalglib/optimization.h>

#include <algorithm>

namespace stewart::safety {
namespace {

template <int MaxRows>
ProjectionStatus SolveWithAlglib(const ProjectionQpN<MaxRows>& qp, Vector6d* x) {
  try {
    alglib::real_2d_array quadratic;
    quadratic.setlength(6, 6);
    alglib::real_1d_array linear, scale;
    linear.setlength(6);
    scale.setlength(6);
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) quadratic[i][j] = i == j ? 1.0 : 0.0;
      linear[i] = -qp.x0(i);
      scale[i] = 1.0;
    }
    alglib::minqpstate state;
    alglib::minqpcreate(6, state);
    alglib::minqpsetquadraticterm(state, quadratic);
    alglib::minqpsetlinearterm(state, linear);
    alglib::minqpsetscale(state, scale);
    if (qp.m > 0) {
      alglib::real_2d_array c;
      c.setlength(qp.m, 7);
      alglib::integer_1d_array type;
      type.setlength(qp.m);
      for (int r = 0; r < qp.m; ++r) {
        for (int i = 0; i < 6; ++i) c[r][i] = qp.a(r, i);
        c[r][6] = qp.b(r);
        type[r] = 1;  // >=
      }
      alglib::minqpsetlc(state, c, type);
    }
    alglib::minqpsetalgobleic(state, 0.0, 0.0, 0.0, 0);  // run to machine precision
    alglib::minqpoptimize(state);
    alglib::real_1d_array solution;
    alglib::minqpreport report;
    alglib::minqpresults(state, solution, report);
    if (report.terminationtype == -3) return ProjectionStatus::kInfeasible;
    if (report.terminationtype <= 0) return ProjectionStatus::kIterationLimit;
    for (int i = 0; i < 6; ++i) (*x)(i) = solution[i];
    return ProjectionStatus::kOptimal;
  } catch (const alglib::ap_error&) {
    return ProjectionStatus::kIterationLimit;
  }
}

}  // namespace

ProjectionStatus AlglibReferenceQp::Solve(const ProjectionQp& qp, Vector6d* x) {
  return SolveWithAlglib(qp, x);
}

ProjectionStatus AlglibReferenceQp::Solve(const UncomposedQp& qp, Vector6d* x) {
  // Presolve: rows with the same unit normal (every position barrier's row
  // has the normal of -H^T qd) are merged into the most restrictive one, an
  // exactly equivalent QP. BLEIC's feasibility phase declares ~1 % of the
  // un-merged QPs "inconsistent" (terminationtype -3) even when a single row
  // is active at the optimum.
  UncomposedQp merged;
  merged.x0 = qp.x0;
  merged.m = 0;
  for (int r = 0; r < qp.m; ++r) {
    const double norm = qp.a.row(r).norm();
    if (!(norm > 0.0)) return ProjectionStatus::kIterationLimit;
    const Eigen::Matrix<double, 1, 6> unit = qp.a.row(r) / norm;
    const double b = qp.b(r) / norm;
    int same = -1;
    for (int k = 0; k < merged.m && same < 0; ++k) {
      if ((merged.a.row(k) - unit).cwiseAbs().maxCoeff() <= 1e-14) same = k;
    }
    if (same >= 0) {
      merged.b(same) = std::max(merged.b(same), b);
    } else {
      merged.a.row(merged.m) = unit;
      merged.b(merged.m) = b;
      ++merged.m;
    }
  }
  return SolveWithAlglib(merged, x);
}

}  // namespace stewart::safety
