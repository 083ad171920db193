// Consistency: the normalised estimation error squared (NEES) of [q, qd],
// summed over Monte-Carlo runs and checkpoints, against the chi-square
// distribution. The truth carries the disturbances the filter models (white
// acceleration, random-walk gyro bias), so a correct EKF is consistent.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>

#include "ekf_harness.h"

namespace stewart::test {
namespace {

// Wilson-Hilferty: quantile of chi-square with `dof` degrees of freedom at
// the standard normal quantile z (relative error < 1e-3 for dof > 100).
double ChiSquareQuantile(double dof, double z) {
  const double a = 2.0 / (9.0 * dof);
  return dof * std::pow(1.0 - a + z * std::sqrt(a), 3);
}

constexpr double kZ995 = 2.5758;  // two-sided 99%
constexpr int kRuns = 20;

struct NeesSums {
  double full = 0.0, q = 0.0, qd = 0.0;
  int n = 0;
};

NeesSums MonteCarloNees(const StackConfig& c, bool disturbed) {
  NeesSums sums;
  const bool dynamics = c.estimator.process_model == EstimatorProcessModel::kDynamics;
  TruthDisturbance d;
  if (disturbed) {
    d.accel_std_mps2 =
        dynamics ? c.estimator.dynamics_accel_std_mps2 : c.estimator.process_accel_std_mps2;
    d.angaccel_std_radps2 = dynamics ? c.estimator.dynamics_angaccel_std_radps2
                                     : c.estimator.process_angaccel_std_radps2;
    d.gyro_bias_walk_radps_per_sqrt_s = c.estimator.gyro_bias_walk_radps_per_sqrt_s;
  }
  for (int run = 0; run < kRuns; ++run) {
    Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
    RunHooks hooks;
    // Checkpoints every 0.5 s from 2 s: far apart compared with the filter's
    // time constants (tens of ms), so their errors are nearly independent.
    hooks.after = [&](int k, const Ekf& f, const TruthSample& t, const UpdateResult& r) {
      if (!r.has_estimate || k < 2000 || k % 500 != 0) return;
      Eigen::Matrix<double, 12, 1> e;
      e << f.x().segment<6>(kEkfQ) - t.state.q, f.x().segment<6>(kEkfQd) - t.state.qd;
      const Eigen::Matrix<double, 12, 12> P = f.P().topLeftCorner<12, 12>();
      sums.full += e.dot(P.llt().solve(e));
      sums.q += e.head<6>().dot(P.topLeftCorner<6, 6>().llt().solve(e.head<6>()));
      sums.qd += e.tail<6>().dot(P.bottomRightCorner<6, 6>().llt().solve(e.tail<6>()));
      ++sums.n;
    };
    RunScenario(c, 100 + static_cast<unsigned>(run), 12.0, 100.0, &ekf, hooks, d);
  }
  std::printf("ANEES [q,qd] %.2f (12 dof), q %.2f, qd %.2f (6 dof), %d checkpoints\n",
              sums.full / sums.n, sums.q / sums.n, sums.qd / sums.n, sums.n);
  EXPECT_EQ(sums.n, kRuns * 21);
  return sums;
}

void ExpectWithinTwoSided(double sum, double dof) {
  EXPECT_GT(sum, ChiSquareQuantile(dof, -kZ995));
  EXPECT_LT(sum, ChiSquareQuantile(dof, kZ995));
}

void ExpectConsistent(const NeesSums& s) {
  ExpectWithinTwoSided(s.full, 12.0 * s.n);
  ExpectWithinTwoSided(s.q, 6.0 * s.n);
  ExpectWithinTwoSided(s.qd, 6.0 * s.n);
}

// The truth's white acceleration is double-integrated without feedback, so
// at the shipped (model-error) noise levels it wanders far from the scenario
// within the 12 s; the equations are checked at a level that keeps it near.
StackConfig DynamicsConfig() {
  StackConfig c = EstimatorTestConfig();
  c.estimator.process_model = EstimatorProcessModel::kDynamics;
  c.estimator.dynamics_accel_std_mps2 = 0.001;
  c.estimator.dynamics_angaccel_std_radps2 = 0.01;
  // The biases' walks with speed answer joints off the model's (a tilt that
  // moves with the platform), which this truth does not have: matched, the
  // filter walks its biases as the truth does. With them (shipped) the
  // filter is a little under-confident here, on the safe side (ANEES of
  // [q, qd] 11.3 against 11.8 without; docs/estimator.md, "Consistency").
  c.estimator.gyro_bias_walk_per_speed = 0.0;
  c.estimator.accel_bias_walk_per_speed = 0.0;
  return c;
}

// Gaussian leg noise only (no ADC) and no inflation: every noise the truth
// has is modelled exactly, so this checks the filter's equations.
TEST(EkfConsistency, MatchedNoiseWithoutQuantisation) {
  StackConfig c = DynamicsConfig();
  c.sensors.leg_adc_bits = 0;
  c.estimator.leg_noise_inflation = 1.0;
  ExpectConsistent(MonteCarloNees(c, true));
}

// The 10-bit ADC: its error is not white; leg_noise_inflation (config)
// is calibrated so the filter stays consistent.
TEST(EkfConsistency, WithTenBitAdcAndConfiguredInflation) {
  const StackConfig c = DynamicsConfig();
  ASSERT_EQ(c.sensors.leg_adc_bits, 10);
  ExpectConsistent(MonteCarloNees(c, true));
}

// The default constant-velocity model on the undisturbed scenario: its
// process noise covers deterministic manoeuvres, so it is conservative in qd
// (docs/estimator.md); it must never be over-confident.
TEST(EkfConsistency, ConstantVelocityNeverOverconfident) {
  const NeesSums s = MonteCarloNees(EstimatorTestConfig(), false);
  EXPECT_LT(s.full, ChiSquareQuantile(12.0 * s.n, kZ995));
  EXPECT_LT(s.q, ChiSquareQuantile(6.0 * s.n, kZ995));
  EXPECT_LT(s.qd, ChiSquareQuantile(6.0 * s.n, kZ995));
}

}  // namespace
}  // namespace stewart::test
