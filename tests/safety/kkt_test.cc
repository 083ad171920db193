// KKT conditions checked directly on the filter's output, for the closed
// form and for the force-limited variant, on random states.
#include <gtest/gtest.h>

#include <cmath>

#include "safety_test_support.h"

namespace stewart::safety::test {
namespace {

void CheckKkt(bool force_limits, CorrectionMetric metric) {
  SafetyConfig config = RichSafetyConfig();
  config.force_limits_enabled = force_limits;
  config.correction_metric = metric;
  SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
  const double f_max = DefaultConfig().actuators.force_limit_n;
  std::mt19937 rng(force_limits ? 23 : 29);
  int checked = 0, active = 0;
  for (int n = 0; n < 5000; ++n) {
    const auto [q, qd, f_des, terms] = RandomFilterInput(&rng);
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(terms, q, qd, f_des, &d);
    ASSERT_TRUE(f.allFinite());
    if (d.infeasible) continue;
    ++checked;
    if (d.mu_p > 0 || d.mu_v > 0) ++active;
    const BarrierEvaluation& b = d.barriers;
    const double scale = f.norm() + f_des.norm() + 1.0;
    // Stationarity of (F - F_des)^T W (F - F_des): F - F_des = W^-1 (mu_p g_p + mu_v g_v -
    // mu_force), with W^-1 = T T^T, T = I for the force metric.
    const Matrix6d t = filter.MetricMap(terms);
    if (metric == CorrectionMetric::kForce) {
      EXPECT_EQ(t, Matrix6d::Identity());
    } else {
      // T T^T is W^-1: W = H^T M^-1 H (kinetic energy) or H^T M^-2 H (task
      // accelerations).
      const Matrix6d m_inv = terms.M.inverse();
      const Matrix6d w = metric == CorrectionMetric::kAcceleration
                             ? Matrix6d(terms.H.transpose() * m_inv * terms.H)
                             : Matrix6d(terms.H.transpose() * m_inv * m_inv * terms.H);
      // M^-2 spans the platform's mass and rotational inertia squared
      // (~1e5 between its entries): rounding relative to the factors' size.
      const double tolerance = metric == CorrectionMetric::kAcceleration
                                   ? 1e-8
                                   : 1e-8 * w.norm() * (t * t.transpose()).norm();
      EXPECT_LE((t * t.transpose() * w - Matrix6d::Identity()).norm(), tolerance) << "sample " << n;
    }
    const Vector6d residual =
        f - f_des - t * t.transpose() * (d.mu_p * b.g_p + d.mu_v * b.g_v - d.mu_force);
    EXPECT_LE(residual.norm(), 1e-10 * scale) << "sample " << n;
    // Dual feasibility.
    EXPECT_GE(d.mu_p, 0.0);
    EXPECT_GE(d.mu_v, 0.0);
    // Primal feasibility and complementary slackness, per condition.
    const double psi_p = b.psi_p + b.g_p.dot(f - f_des);
    const double psi_v = b.psi_v + b.g_v.dot(f - f_des);
    const double tol_p = 1e-10 * (std::fabs(b.psi_p) + b.g_p.norm() * scale);
    const double tol_v = 1e-10 * (std::fabs(b.psi_v) + b.g_v.norm() * scale);
    EXPECT_GE(psi_p, -tol_p) << "sample " << n;
    EXPECT_GE(psi_v, -tol_v) << "sample " << n;
    EXPECT_LE(std::fabs(d.mu_p * psi_p), d.mu_p * tol_p + 1e-300) << "sample " << n;
    EXPECT_LE(std::fabs(d.mu_v * psi_v), d.mu_v * tol_v + 1e-300) << "sample " << n;
    ExpectForceLimitsKkt(f, d.mu_force, force_limits, f_max, n);
  }
  EXPECT_GT(checked, 4000);
  EXPECT_GT(active, 1000);
}

TEST(Kkt, ClosedForm) { CheckKkt(false, CorrectionMetric::kForce); }
TEST(Kkt, ForceLimited) { CheckKkt(true, CorrectionMetric::kForce); }
TEST(Kkt, ClosedFormAccelerationMetric) { CheckKkt(false, CorrectionMetric::kAcceleration); }
TEST(Kkt, ForceLimitedAccelerationMetric) { CheckKkt(true, CorrectionMetric::kAcceleration); }
TEST(Kkt, ClosedFormTaskAccelerationMetric) {
  CheckKkt(false, CorrectionMetric::kTaskAcceleration);
}
TEST(Kkt, ForceLimitedTaskAccelerationMetric) {
  CheckKkt(true, CorrectionMetric::kTaskAcceleration);
}

}  // namespace
}  // namespace stewart::safety::test
