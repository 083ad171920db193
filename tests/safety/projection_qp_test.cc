// The projection QP's final answer on ill-conditioned active sets: two nearly
// parallel normals active at once with large multipliers. A position row and
// a velocity row near a limit look like this; on some of those QPs the dual
// active-set iterations alone leave an active row off by more than 1e-12
// relative, and the final re-solve (projection_qp.cc, Polish) must take it to rounding
// whether or not the iterations' answer looked good enough to skip it.
#include "stewart/safety/projection_qp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "stewart/safety/uncomposed_qp.h"
#include "uncomposed_support.h"

namespace stewart::safety::test {
namespace {

Vector6d RandomUnit(std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d v;
  for (int i = 0; i < 6; ++i) v(i) = n(*rng);
  return v.normalized();
}

// A QP whose optimum x_star has rows 0 and 1 active with multipliers mu0, mu1,
// their unit normals `gap` apart, and a third, well-conditioned active row;
// built backwards: x0 = x_star - sum mu_i a_i, b_i = a_i^T x_star.
struct KnownOptimum {
  ProjectionQp qp;
  Vector6d x_star;
};

KnownOptimum NearlyParallelRows(double gap, double mu0, double mu1, std::mt19937_64* rng) {
  KnownOptimum k;
  const Vector6d a0 = RandomUnit(rng);
  Vector6d w = RandomUnit(rng);
  w -= w.dot(a0) * a0;
  const Vector6d a1 = (a0 + gap * w.normalized()).normalized();
  Vector6d a2 = RandomUnit(rng);
  a2 -= a2.dot(a0) * a0;
  a2.normalize();
  k.x_star = RandomUnit(rng);
  k.qp.x0 = k.x_star - mu0 * a0 - mu1 * a1 - 1.0 * a2;
  const Vector6d rows[3] = {a0, a1, a2};
  for (const Vector6d& a : rows) {
    k.qp.a.row(k.qp.m) = a.transpose();
    k.qp.b(k.qp.m++) = a.dot(k.x_star);
  }
  // Inactive rows nearly parallel to the pair, just slack at x_star.
  for (int i = 0; i < 4; ++i) {
    Vector6d v = RandomUnit(rng);
    v -= v.dot(a0) * a0;
    const Vector6d a = (a0 + gap * (0.5 + i) * v.normalized()).normalized();
    k.qp.a.row(k.qp.m) = a.transpose();
    k.qp.b(k.qp.m++) = a.dot(k.x_star) - 1e-9 * mu0;
  }
  return k;
}

// Built around a known optimum: the solver finds it, its multipliers
// non-negative and its active rows held to rounding, for multipliers up to
// 1e9 on normals 1e-6 apart.
TEST(ProjectionQp, NearlyParallelActiveRowsKnownOptimum) {
  std::mt19937_64 rng(20261206);
  int cases = 0;
  for (const double gap : {1e-3, 1e-5, 1e-6}) {
    for (const double mu : {1e3, 1e6, 1e9}) {
      for (int trial = 0; trial < 25; ++trial, ++cases) {
        const KnownOptimum k = NearlyParallelRows(gap, mu, 0.5 * mu, &rng);
        const ProjectionResult r = SolveProjectionQp(k.qp);
        ASSERT_EQ(r.status, ProjectionStatus::kOptimal) << "gap " << gap << " mu " << mu;
        const double x_norm = r.x.norm() + k.qp.x0.norm();
        for (int i = 0; i < k.qp.m; ++i) {
          const double scale = std::fabs(k.qp.b(i)) + k.qp.a.row(i).norm() * x_norm;
          const double slack = k.qp.a.row(i).dot(r.x) - k.qp.b(i);
          EXPECT_GE(slack, -1e-13 * scale) << "row " << i << " gap " << gap << " mu " << mu;
          EXPECT_GE(r.mu(i), 0.0) << "row " << i;
          if (r.mu(i) > 0.0) {
            EXPECT_LE(std::fabs(slack), 1e-13 * scale)
                << "active row " << i << " gap " << gap << " mu " << mu;
          }
        }
        // Stationarity: x - x0 = sum mu_i a_i.
        Vector6d combination = Vector6d::Zero();
        double mu_a = 0.0;
        for (int i = 0; i < k.qp.m; ++i) {
          combination += r.mu(i) * k.qp.a.row(i).transpose();
          mu_a += r.mu(i) * k.qp.a.row(i).norm();
        }
        EXPECT_LE((r.x - k.qp.x0 - combination).norm(), 1e-12 * (mu_a + k.qp.x0.norm()));
        // The optimum is unique: the one the QP was built around, to the
        // conditioning of the nearly parallel pair.
        EXPECT_LE((r.x - k.x_star).norm(), 1e-14 * mu / gap + 1e-12)
            << "gap " << gap << " mu " << mu;
      }
    }
  }
  EXPECT_EQ(cases, 225);
}

// The QPs the un-composed filter poses at states a hair from a position
// limit (the other axes still or moving), whose position and velocity rows
// bind together with nearly parallel normals (uncomposed_support.h): every
// active row holds to 1e-12 of the QP's scale (3e-15 measured). Without
// the final re-solve rows of some of these QPs are off by more than that.
TEST(ProjectionQp, FilterQpsNearAPositionLimitHoldTheirActiveRows) {
  for (const bool force_limits : {false, true}) {
    SafetyConfig config = RichSafetyConfig();
    config.variant = SafetyVariant::kUncomposed;
    config.force_limits_enabled = force_limits;
    SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
    std::mt19937 rng(force_limits ? 13 : 17);
    int solved = 0, multi_row = 0;
    for (int n = 0; n < 600; ++n) {
      NearOneLimit x;
      if (!DrawNearPositionLimit(filter, n % 2 == 0 ? 1e-5 : 2e-3, &rng, &x)) continue;
      SafetyDiagnostics d;
      filter.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &d);
      UncomposedQp qp;
      const Matrix6d t = filter.MetricMap(x.terms);
      if (!filter.BuildUncomposedQp(x.terms, x.qd, t, d.barriers, x.f_des, &qp)) continue;
      const ProjectionResultN<kMaxUncomposedQpRows> r = SolveProjectionQp(qp);
      if (r.status != ProjectionStatus::kOptimal) continue;
      ++solved;
      const double scale = 1.0 + r.x.norm() + qp.x0.norm();
      int active = 0;
      for (int i = 0; i < qp.m; ++i) {
        const double slack = (qp.a.row(i).dot(r.x) - qp.b(i)) / qp.a.row(i).norm();
        ASSERT_GE(r.mu(i), 0.0) << "sample " << n << " row " << i;
        ASSERT_GE(slack, -1e-12 * scale) << "sample " << n << " row " << i;
        if (r.mu(i) > 0.0) {
          ++active;
          ASSERT_LE(std::fabs(slack), 1e-12 * scale) << "sample " << n << " active row " << i;
        }
      }
      if (active > 1) ++multi_row;
    }
    // The draw reaches what it is for: solved QPs, several rows binding.
    EXPECT_GT(solved, 300) << "force limits " << force_limits;
    EXPECT_GT(multi_row, 200) << "force limits " << force_limits;
  }
}

}  // namespace
}  // namespace stewart::safety::test
