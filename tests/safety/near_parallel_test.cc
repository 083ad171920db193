// The exact case analysis (two_constraint_qp.h) on nearly (anti)parallel
// normals, sin^2 of their angle swept over [1e-14, 1e-4]: bounded output,
// and either the QP's optimum or the documented flagged fallback. The
// reference enumerates every active set in long double, independently of
// the case order and thresholds of the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "stewart/safety/two_constraint_qp.h"

namespace stewart::safety {
namespace {

using Real = long double;

struct ClpReference {
  bool feasible = false;
  Vector6d d = Vector6d::Zero();  // F* - F_des
};

Real Dot(const Vector6d& a, const Vector6d& b) {
  Real s = 0;
  for (int i = 0; i < 6; ++i) s += static_cast<Real>(a(i)) * static_cast<Real>(b(i));
  return s;
}

// min ||d||^2 s.t. psi_i + g_i.d >= 0: the unique KKT point of a strictly
// convex QP, found by trying every active set ({}, {p}, {v}, {p, v}) and
// keeping the feasible one of least norm.
ClpReference ExactQp(const TwoConstraintProblem& pr) {
  const Real pp = Dot(pr.g_p, pr.g_p), vv = Dot(pr.g_v, pr.g_v), pv = Dot(pr.g_p, pr.g_v);
  // Lagrange's identity: the Gram determinant without cancellation.
  Real det = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i + 1; j < 6; ++j) {
      const Real c =
          static_cast<Real>(pr.g_p(i)) * pr.g_v(j) - static_cast<Real>(pr.g_p(j)) * pr.g_v(i);
      det += c * c;
    }
  }
  const Real psi_p = pr.psi_p, psi_v = pr.psi_v;
  ClpReference best;
  Real best_norm2 = INFINITY;
  auto consider = [&](Real mu_p, Real mu_v) {
    if (mu_p < 0 || mu_v < 0) return;
    // Feasibility to long double rounding of the terms.
    const Real after_p = psi_p + mu_p * pp + mu_v * pv;
    const Real after_v = psi_v + mu_p * pv + mu_v * vv;
    const Real tol = 1e-17L;
    if (after_p < -tol * (std::fabs(psi_p) + mu_p * pp + std::fabs(mu_v * pv))) return;
    if (after_v < -tol * (std::fabs(psi_v) + std::fabs(mu_p * pv) + mu_v * vv)) return;
    const Real norm2 = mu_p * mu_p * pp + 2 * mu_p * mu_v * pv + mu_v * mu_v * vv;
    if (norm2 < best_norm2) {
      best_norm2 = norm2;
      best.feasible = true;
      for (int i = 0; i < 6; ++i) {
        best.d(i) = static_cast<double>(mu_p * pr.g_p(i) + mu_v * pr.g_v(i));
      }
    }
  };
  consider(0, 0);
  consider(-psi_p / pp, 0);
  consider(0, -psi_v / vv);
  if (det > 0) consider((-psi_p * vv + psi_v * pv) / det, (-psi_v * pp + psi_p * pv) / det);
  return best;
}

Real Sin2(const TwoConstraintProblem& pr) {
  const Real pp = Dot(pr.g_p, pr.g_p), vv = Dot(pr.g_v, pr.g_v);
  Real det = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i + 1; j < 6; ++j) {
      const Real c =
          static_cast<Real>(pr.g_p(i)) * pr.g_v(j) - static_cast<Real>(pr.g_p(j)) * pr.g_v(i);
      det += c * c;
    }
  }
  return det / (pp * vv);
}

double LogUniform(std::mt19937* rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(*rng));
}

// sqrt(2) / sin a of the case-4 correction, at the widest anti-parallel band.
constexpr double kBoundFactor = 1415.0;

TEST(DegenerateNearParallel, BoundedAndTheQpOrTheFlaggedFallbackOverSin2From1e14To1e4) {
  std::mt19937 rng(71);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int case4_opposing = 0, band_fallback = 0, checked = 0, within_slack = 0;
  double worst_ratio = 0.0, worst_objective = 0.0;
  for (double log_sin2 = -14.0; log_sin2 <= -4.0 + 1e-9; log_sin2 += 0.125) {
    const double sin_a = std::sqrt(std::pow(10.0, log_sin2));
    for (const double direction : {1.0, -1.0}) {
      for (int n = 0; n < 400; ++n) {
        TwoConstraintProblem pr;
        pr.has_p = pr.has_v = true;
        const double size_p = LogUniform(&rng, 1e-3, 1e3), size_v = LogUniform(&rng, 1e-3, 1e3);
        pr.g_p = Vector6d::Unit(0) * size_p;
        pr.g_v = (Vector6d::Unit(0) * (direction * std::sqrt(1.0 - sin_a * sin_a)) +
                  Vector6d::Unit(1) * sin_a) *
                 size_v;
        // Offsets on the scale of the normals, so that the slab between
        // opposing normals is as often empty as not.
        pr.psi_p = unit(rng) * size_p * size_p;
        pr.psi_v = unit(rng) * size_v * size_v;
        const Real sin2 = Sin2(pr);
        const bool opposing = pr.g_p.dot(pr.g_v) < 0.0;
        const double own =
            std::fabs(pr.psi_p) / pr.g_p.norm() + std::fabs(pr.psi_v) / pr.g_v.norm();
        const TwoConstraintSolution s = SolveExactKkt(pr);
        const Vector6d d = s.mu_p * pr.g_p + s.mu_v * pr.g_v;
        const ClpReference ref = ExactQp(pr);
        ++checked;
        char where[200];
        std::snprintf(
            where, sizeof where, "sin^2 %.3Lg %s sample %d psi %.17g %.17g |g| %.17g %.17g", sin2,
            opposing ? "opposing" : "same direction", n, pr.psi_p, pr.psi_v, size_p, size_v);
        ASSERT_TRUE(d.allFinite()) << where;
        // Bounded: never more than the band's factor times the conditions'
        // own corrections.
        worst_ratio = std::fmax(worst_ratio, d.norm() / own);
        ASSERT_LE(d.norm(), kBoundFactor * own) << where;
        if (s.feasible) {
          // The QP's optimum: feasible within the case analysis' stated
          // relative slack (1e-12 of the terms), and no larger than the
          // exact optimum (the slack can only make it smaller). Where the
          // exact QP is infeasible by less than that slack (a slab empty by
          // 1e-13), feasible within the slack is all there is to check.
          // The terms each condition sums at F*, and the relative rounding
          // of the 2x2 Gram solve, eps / sin^2 (its determinant cancels).
          const double rel = 2e-12 + 4e-16 / static_cast<double>(sin2);
          const double terms_p = std::fabs(pr.psi_p) + s.mu_p * pr.g_p.squaredNorm() +
                                 s.mu_v * std::fabs(pr.g_p.dot(pr.g_v));
          const double terms_v = std::fabs(pr.psi_v) + s.mu_v * pr.g_v.squaredNorm() +
                                 s.mu_p * std::fabs(pr.g_p.dot(pr.g_v));
          EXPECT_GE(pr.psi_p + pr.g_p.dot(d), -rel * terms_p) << where;
          EXPECT_GE(pr.psi_v + pr.g_v.dot(d), -rel * terms_v) << where;
          if (!ref.feasible) {
            ++within_slack;
            continue;
          }
          const double objective = (d.norm() - ref.d.norm()) / std::fmax(ref.d.norm(), 1e-300);
          worst_objective = std::fmax(worst_objective, objective);
          EXPECT_LE(d.norm(), ref.d.norm() * (1.0 + 1e-9) + 1e-12 * own) << where;
          // Away from the degenerate angles, the same point.
          if (sin2 >= 1e-6L) {
            EXPECT_LE((d - ref.d).norm(), 1e-9 * std::fmax(ref.d.norm(), own)) << where;
          }
          if (opposing && s.filter_case == FilterCase::kBoth) ++case4_opposing;
        } else {
          EXPECT_EQ(s.filter_case, FilterCase::kInfeasible) << where;
          EXPECT_EQ(s.mu_p, 0.0);
          EXPECT_EQ(s.mu_v, 0.0);
          // Infeasible only where the QP is, or in the documented band of
          // opposing normals treated as anti-parallel.
          const bool in_band =
              opposing && sin2 <= static_cast<Real>(kOpposingParallelSin2) * 1.001L;
          if (ref.feasible) {
            ASSERT_TRUE(in_band) << where;
            ++band_fallback;
          }
          // The fallback: bounded, keeps the position condition exactly.
          const TwoConstraintSolution fb = SolveInfeasibleFallback(pr);
          const Vector6d d_fb = fb.mu_p * pr.g_p + fb.mu_v * pr.g_v;
          EXPECT_FALSE(fb.feasible);
          ASSERT_LE(d_fb.norm(), own * (1.0 + 1e-12)) << where;
          EXPECT_GE(pr.psi_p + pr.g_p.dot(d_fb), -1e-12 * std::fabs(pr.psi_p)) << where;
        }
      }
    }
  }
  std::printf(
      "%d problems: worst |F* - F_des| / own corrections %.4g, worst objective excess %.3g; "
      "opposing case 4 %d, band fallbacks %d, feasible only within the slack %d\n",
      checked, worst_ratio, worst_objective, case4_opposing, band_fallback, within_slack);
  // Both sides of the band were exercised.
  EXPECT_GT(case4_opposing, 100);
  EXPECT_GT(band_fallback, 100);
}

}  // namespace
}  // namespace stewart::safety
