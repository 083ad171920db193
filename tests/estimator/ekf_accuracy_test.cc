// Accuracy of the EKF on simulated noisy sensors (10-bit ADC legs, gyro with
// bias, accelerometer) along the paper's scenario. The bounds are those
// stated in docs/estimator.md; measured values are printed for the docs.
#include <gtest/gtest.h>

#include <cstdio>

#include "ekf_harness.h"

namespace stewart::test {
namespace {

struct Bounds {
  double position_m, angle_rad, velocity_mps, rate_radps;
};

// docs/estimator.md, "Measured accuracy".
constexpr Bounds kConstantVelocityBounds{1e-4, 1e-4, 1e-3, 1e-3};
// With the model error d estimated and honest process noise (0.05 m/s^2,
// 0.5 rad/s^2) the rates are noisier than with the exact-model tuning
// (0.3 mrad/s before): docs/estimator.md, "Model error".
constexpr Bounds kDynamicsBounds{5e-5, 5e-5, 4e-4, 7e-4};

void Print(const char* name, const RunStats& s) {
  const Vector6d q = s.q_err.Rms(), qd = s.qd_err.Rms();
  std::printf("%-26s q [mm, mrad]     %6.3f %6.3f %6.3f | %6.3f %6.3f %6.3f\n", name, 1e3 * q(0),
              1e3 * q(1), 1e3 * q(2), 1e3 * q(3), 1e3 * q(4), 1e3 * q(5));
  std::printf("%-26s qd [mm/s, mrad/s] %6.3f %6.3f %6.3f | %6.3f %6.3f %6.3f  |b_g err| %.1e\n", "",
              1e3 * qd(0), 1e3 * qd(1), 1e3 * qd(2), 1e3 * qd(3), 1e3 * qd(4), 1e3 * qd(5),
              s.final_bias_error.norm());
}

void ExpectWithin(const RunStats& s, const Bounds& b) {
  const Vector6d q = s.q_err.Rms(), qd = s.qd_err.Rms();
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(q(i), b.position_m) << "axis " << i;
    EXPECT_LT(q(3 + i), b.angle_rad) << "axis " << 3 + i;
    EXPECT_LT(qd(i), b.velocity_mps) << "axis " << i;
    EXPECT_LT(qd(3 + i), b.rate_radps) << "axis " << 3 + i;
  }
  // The gyro bias (2e-3 rad/s in the config) is learned to a few percent.
  EXPECT_LT(s.final_bias_error.norm(), 1e-4);
  EXPECT_EQ(s.Count(kGateLegs), 0);
  EXPECT_EQ(s.with_estimate + 1000, s.samples);  // every sample after the settle second
}

StackConfig WithModel(EstimatorProcessModel model, bool accel = true) {
  StackConfig c = EstimatorTestConfig();
  c.estimator.process_model = model;
  c.estimator.use_accelerometer = accel;
  return c;
}

TEST(EkfAccuracy, DefaultConfigIsDynamicsAndNotPerfectState) {
  // Chosen in the closed loop (docs/estimator.md, "Choice of process model").
  EXPECT_EQ(EstimatorTestConfig().estimator.process_model, EstimatorProcessModel::kDynamics);
  EXPECT_FALSE(EstimatorTestConfig().estimator.perfect_state);
}

/// The paper scenario (noise seed 1) on the sensors of `truth`, estimated by
/// the EKF of `filter`; printed as `name`.
RunStats RunPaper(const char* name, const StackConfig& truth, const StackConfig& filter) {
  Ekf ekf = MakeEkf(filter);
  const RunStats s = RunScenario(truth, 1, ScenarioTruth::kDurationS, 1.0, &ekf);
  Print(name, s);
  return s;
}

TEST(EkfAccuracy, ConstantVelocityModelOnPaperScenario) {
  const StackConfig c = WithModel(EstimatorProcessModel::kConstantVelocity);
  ExpectWithin(RunPaper("constant velocity", c, c), kConstantVelocityBounds);
}

TEST(EkfAccuracy, DynamicsModelOnPaperScenario) {
  const StackConfig c = WithModel(EstimatorProcessModel::kDynamics);
  const RunStats s = RunPaper("dynamics (exact model)", c, c);
  ExpectWithin(s, kDynamicsBounds);
  EXPECT_EQ(s.Count(kEventNoCommand), 0);
}

// Ablations for docs/estimator.md: what the accelerometer adds, and what a
// wrong model (platform and rod 10% lighter, no friction) does to each model.
TEST(EkfAccuracy, AblationsAndModelMismatch) {
  for (auto model : {EstimatorProcessModel::kConstantVelocity, EstimatorProcessModel::kDynamics}) {
    const StackConfig c = WithModel(model, false);
    RunPaper(
        model == EstimatorProcessModel::kDynamics ? "dynamics, no accel" : "const vel, no accel", c,
        c);
  }
  RunStats mismatch[2];
  int i = 0;
  for (auto model : {EstimatorProcessModel::kConstantVelocity, EstimatorProcessModel::kDynamics}) {
    const StackConfig c = WithModel(model);
    StackConfig wrong = c;
    wrong.platform.platform_mass_kg *= 0.9;
    wrong.platform.leg.rod_mass_kg *= 0.9;
    wrong.actuators.viscous_friction_nspm = 0.0;
    mismatch[i] = RunPaper(i == 0 ? "const vel, mass -10%" : "dynamics, mass -10%", c, wrong);
    std::printf("  gated leg updates %d, divergences %d\n", mismatch[i].Count(kGateLegs),
                mismatch[i].Count(kEventDiverged));
    ++i;
  }
  // The constant-velocity model does not use the mass: unaffected.
  ExpectWithin(mismatch[0], kConstantVelocityBounds);
  // The dynamics model estimates the mass error as part of d: as accurate
  // as with the exact model (without d it exceeded the constant-velocity
  // bounds here: docs/estimator.md, "Model error").
  ExpectWithin(mismatch[1], kDynamicsBounds);
  EXPECT_EQ(mismatch[1].Count(kEventDiverged), 0);
}

}  // namespace
}  // namespace stewart::test
