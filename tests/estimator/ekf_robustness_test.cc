// Robustness of the EKF: bad initial guesses, outliers, NaN and out-of-range
// readings, and bad sample times are rejected and counted, never published
// as NaN, and the filter recovers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "ekf_harness.h"
#include "stewart/estimator/measurement_models.h"
#include "stewart/estimator/process_model.h"
#include "stewart/model/dynamics.h"

namespace stewart::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTorqueNm = 0.05;  // phantom torque about x (N m)

// The default model's accuracy bounds (docs/estimator.md).
void ExpectAccurate(const RunStats& s) {
  const Vector6d q = s.q_err.Rms(), qd = s.qd_err.Rms();
  EXPECT_LT(q.head<3>().maxCoeff(), 1e-4);
  EXPECT_LT(q.tail<3>().maxCoeff(), 1e-4);
  EXPECT_LT(qd.head<3>().maxCoeff(), 1e-3);
  EXPECT_LT(qd.tail<3>().maxCoeff(), 1e-3);
}

RunHooks ExpectFiniteEstimates() {
  RunHooks hooks;
  hooks.after = [](int, const Ekf& f, const TruthSample&, const UpdateResult& r) {
    if (!r.has_estimate) return;
    const Estimate e = f.estimate();
    ASSERT_TRUE(e.q.allFinite() && e.qd.allFinite() && e.q_std.allFinite() && e.qd_std.allFinite());
  };
  return hooks;
}

TEST(EkfRobustness, InitialisesFromForwardKinematicsOfFirstLegs) {
  const StackConfig& c = EstimatorTestConfig();
  ScenarioTruth truth(c, 3);
  Ekf ekf = MakeEkf(c);
  truth.Next();
  const TruthSample s = truth.Next();  // not at home: x already moving
  const UpdateResult r = ekf.Update(s.sensors);
  ASSERT_TRUE(r.has_estimate);
  EXPECT_TRUE(r.Has(kEventInitialized));
  EXPECT_TRUE(ekf.estimate().initializing);
  // One quantised reading: within a few ADC steps (0.2 mm) of the truth.
  EXPECT_LT((ekf.estimate().q - s.state.q).head<3>().cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT((ekf.estimate().q - s.state.q).tail<3>().cwiseAbs().maxCoeff(), 5e-3);
}

TEST(EkfRobustness, RecoversFromBadInitialGuessWithHonestCovariance) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  Vector6d q0 = c.home_pose;
  q0 += (Vector6d() << 0.01, -0.01, 0.005, 0.03, -0.03, 0.02).finished();
  EkfVector std;
  std << Vector6d::Constant(0.02), Vector6d::Constant(0.05),
      Vector3d::Constant(c.estimator.initial_disturbance_std_n),
      Vector3d::Constant(c.estimator.initial_disturbance_std_nm), Vector3d::Constant(0.01);
  ekf.Initialize(-1000, q0, Vector6d::Constant(0.02), std);
  const RunStats s = RunScenario(c, 4, 6.0, 1.0, &ekf, ExpectFiniteEstimates());
  ExpectAccurate(s);
  EXPECT_EQ(s.Count(kEventDiverged), 0);
}

TEST(EkfRobustness, OverconfidentBadGuessIsDetectedAsDivergenceAndRecovers) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  Vector6d q0 = c.home_pose;
  q0(0) += 0.01;  // 10 mm off, claimed to 1 um
  ekf.Initialize(-1000, q0, Vector6d::Zero(), EkfVector::Constant(1e-6));
  bool saw_diverged_status = false;
  RunHooks hooks = ExpectFiniteEstimates();
  const auto finite = hooks.after;
  hooks.after = [&](int k, const Ekf& f, const TruthSample& t, const UpdateResult& r) {
    finite(k, f, t, r);
    if (r.has_estimate && f.estimate().diverged) saw_diverged_status = true;
  };
  const RunStats s = RunScenario(c, 5, 6.0, 1.0, &ekf, hooks);
  EXPECT_EQ(s.Count(kEventDiverged), 1);
  EXPECT_EQ(s.Count(kGateLegs), c.estimator.divergence_rejections);
  EXPECT_TRUE(saw_diverged_status);
  ExpectAccurate(s);
}

TEST(EkfRobustness, AGyroThatKeepsDisagreeingIsFollowedNotGatedUntilTheStateJumps) {
  // The model mispredicts the rotation: for 0.1 s the EKF is told of leg
  // forces with a torque about x the platform never felt. The gyro then
  // disagrees sample after sample. Gated throughout, the rates drifted on the
  // model alone while their covariance with the pose and the velocity grew,
  // and the first reading let back in moved the whole state at once.
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  const DynamicsTerms home = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  const Vector6d torque = (Vector6d() << 0.0, 0.0, 0.0, kTorqueNm, 0.0, 0.0).finished();
  const Vector6d phantom_n = home.H.partialPivLu().solve(torque);
  constexpr int kStart = 3000, kEnd = 3100;
  RunHooks hooks;
  hooks.command = [&](int k, Vector6d* force_n) {
    if (k >= kStart && k < kEnd) *force_n += phantom_n;
  };
  double worst_rate_error = 0.0, worst_position_error = 0.0, worst_speed_error = 0.0;
  int gyro_gated_in_a_row = 0, longest_gyro_gating = 0;
  hooks.after = [&](int k, const Ekf& f, const TruthSample& truth, const UpdateResult& r) {
    gyro_gated_in_a_row = r.Has(kGateGyro) ? gyro_gated_in_a_row + 1 : 0;
    longest_gyro_gating = std::max(longest_gyro_gating, gyro_gated_in_a_row);
    if (k < kStart || !r.has_estimate) return;
    const Estimate e = f.estimate();
    worst_rate_error =
        std::max(worst_rate_error, (e.qd - truth.state.qd).tail<3>().cwiseAbs().maxCoeff());
    worst_speed_error =
        std::max(worst_speed_error, (e.qd - truth.state.qd).head<3>().cwiseAbs().maxCoeff());
    worst_position_error =
        std::max(worst_position_error, (e.q - truth.state.q).head<3>().cwiseAbs().maxCoeff());
  };
  const RunStats s = RunScenario(c, 6, 4.0, 1.0, &ekf, hooks);
  // Without the re-opening (measured): the gyro gated 900 samples in a row,
  // the rates 0.19 rad/s and the velocity 36 mm/s off, and a restart.
  EXPECT_GT(s.Count(kEventRatesReopened), 0);
  EXPECT_LE(longest_gyro_gating, 2);
  EXPECT_EQ(s.Count(kEventDiverged), 0);
  EXPECT_LT(worst_rate_error, 0.05);
  EXPECT_LT(worst_speed_error, 0.005);
  EXPECT_LT(worst_position_error, 1e-3);
}

TEST(EkfRobustness, OutliersAreGatedAndCounted) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  int leg_outliers = 0, gyro_outliers = 0;
  RunHooks hooks = ExpectFiniteEstimates();
  hooks.before = [&](int k, SensorSample* s) {
    if (k < 500) return;
    if (k % 97 == 0) {
      s->leg_length_m(k % 6) += 0.003;  // 3 mm: ~40 sigma, inside the stroke
      ++leg_outliers;
    }
    if (k % 89 == 0) {
      s->gyro_radps(k % 3) += 0.3;
      ++gyro_outliers;
    }
  };
  const RunStats s = RunScenario(c, 6, 20.0, 1.0, &ekf, hooks);
  EXPECT_GT(leg_outliers, 100);
  EXPECT_EQ(s.Count(kGateLegs), leg_outliers);
  EXPECT_EQ(s.Count(kGateGyro), gyro_outliers);
  EXPECT_EQ(s.Count(kEventDiverged), 0);
  ExpectAccurate(s);
}

TEST(EkfRobustness, NonFiniteAndOutOfRangeReadingsAreRejectedAndCounted) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  RunHooks hooks = ExpectFiniteEstimates();
  int legs_nan = 0, legs_range = 0, gyro_bad = 0, accel_bad = 0, orient_bad = 0;
  hooks.before = [&](int k, SensorSample* s) {
    if (k < 300) return;
    switch (k % 50) {
      case 0:
        s->leg_length_m(2) = kNaN;
        ++legs_nan;
        break;
      case 10:
        s->leg_length_m(4) = 0.1;
        ++legs_range;
        break;  // far below the stroke
      case 20:
        s->gyro_radps(1) = kInf;
        ++gyro_bad;
        break;
      case 30:
        s->accel_mps2(0) = kNaN;
        ++accel_bad;
        break;
      case 40:
        s->has_orientation = true;
        s->orientation_rpy_rad(2) = kNaN;
        ++orient_bad;
        break;
      case 45:
        s->gyro_radps(0) = 1e3;
        ++gyro_bad;
        break;  // out of range
      default:
        break;
    }
  };
  const RunStats s = RunScenario(c, 7, 10.0, 1.0, &ekf, hooks);
  EXPECT_EQ(s.Count(kRejectLegsNonFinite), legs_nan);
  EXPECT_EQ(s.Count(kRejectLegsRange), legs_range);
  EXPECT_EQ(s.Count(kRejectGyroInvalid), gyro_bad);
  EXPECT_EQ(s.Count(kRejectAccelInvalid), accel_bad);
  EXPECT_EQ(s.Count(kRejectOrientationInvalid), orient_bad);
  EXPECT_GT(legs_nan, 100);
  // The other groups of a sample are still used: an estimate every sample.
  EXPECT_EQ(s.with_estimate + 1000, s.samples);
  ExpectAccurate(s);
}

TEST(EkfRobustness, NoEstimateBeforeAValidLegReading) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  ScenarioTruth truth(c, 8);
  SensorSample bad = truth.Next().sensors;
  bad.leg_length_m(0) = kNaN;
  UpdateResult r = ekf.Update(bad);
  EXPECT_FALSE(r.has_estimate);
  EXPECT_TRUE(r.Has(kRejectLegsNonFinite));
  EXPECT_FALSE(ekf.initialized());
  r = ekf.Update(truth.Next().sensors);
  EXPECT_TRUE(r.has_estimate);
  EXPECT_TRUE(r.Has(kEventInitialized));
}

// A sensor that keeps sending samples without a usable leg reading (every
// leg NaN): the prediction bridges divergence_rejections samples, then the
// filter gives the estimate up until the legs read again.
TEST(EkfRobustness, SamplesWithoutLegsAreBridgedThenTheEstimateIsGivenUp) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  ScenarioTruth truth(c, 10);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(ekf.Update(truth.Next().sensors).has_estimate);
  int with_estimate = 0, diverged = 0;
  for (int k = 0; k < 200; ++k) {
    SensorSample s = truth.Next().sensors;
    s.leg_length_m.setConstant(kNaN);
    const UpdateResult r = ekf.Update(s);
    EXPECT_TRUE(r.Has(kRejectLegsNonFinite));
    with_estimate += r.has_estimate ? 1 : 0;
    diverged += r.Has(kEventDiverged) ? 1 : 0;
  }
  EXPECT_EQ(with_estimate, c.estimator.divergence_rejections - 1);
  EXPECT_EQ(diverged, 1);
  EXPECT_FALSE(ekf.initialized());
  const UpdateResult back = ekf.Update(truth.Next().sensors);
  EXPECT_TRUE(back.has_estimate);
  EXPECT_TRUE(back.Has(kEventInitialized));
}

TEST(EkfRobustness, BadSampleTimesAreRejectedOrRestart) {
  const StackConfig& c = EstimatorTestConfig();
  Ekf ekf = MakeEkf(c);
  ScenarioTruth truth(c, 9);
  TruthSample t;
  for (int k = 0; k < 100; ++k) {
    t = truth.Next();
    ASSERT_TRUE(ekf.Update(t.sensors).has_estimate);
  }
  const EkfVector before = ekf.x();
  // A repeated and a backwards sample: ignored, state untouched.
  UpdateResult r = ekf.Update(t.sensors);
  EXPECT_TRUE(r.Has(kRejectTime));
  EXPECT_FALSE(r.has_estimate);
  SensorSample back = t.sensors;
  back.utime -= 5000;
  EXPECT_TRUE(ekf.Update(back).Has(kRejectTime));
  EXPECT_EQ(ekf.x(), before);
  // A gap longer than max_dt_s: restart from the legs.
  for (int k = 0; k < 200; ++k) t = truth.Next();
  r = ekf.Update(t.sensors);
  EXPECT_TRUE(r.has_estimate);
  EXPECT_TRUE(r.Has(kEventReinitTimeGap));
  EXPECT_TRUE(r.Has(kEventInitialized));
  EXPECT_LT((ekf.estimate().q - t.state.q).head<3>().cwiseAbs().maxCoeff(), 1e-3);
}

TEST(EkfRobustness, NonFiniteCommandIsIgnored) {
  StackConfig c = EstimatorTestConfig();
  c.estimator.process_model = EstimatorProcessModel::kDynamics;
  Ekf ekf = MakeEkf(c);
  ScenarioTruth truth(c, 10);
  ASSERT_TRUE(ekf.Update(truth.Next().sensors).has_estimate);
  ekf.SetForceCommand(0, Vector6d::Constant(kNaN));
  const UpdateResult r = ekf.Update(truth.Next().sensors);
  EXPECT_TRUE(r.Has(kEventNoCommand));  // fell back to constant velocity
  EXPECT_TRUE(ekf.x().allFinite());
}

// The gyro Jacobian (analytic rate block + differenced angle block) against
// a finite difference of the whole measurement function.
TEST(EkfModels, GyroAndAccelJacobiansMatchFiniteDifferences) {
  EkfVector x = EkfVector::Zero();
  x.segment<6>(kEkfQ) << 0.02, -0.01, 0.42, 0.05, -0.04, 0.1;
  x.segment<6>(kEkfQd) << 0.01, 0.02, -0.01, 0.3, -0.2, 0.25;
  x.segment<3>(kEkfGyroBias) << 0.001, -0.002, 0.003;
  const Vector6d qdd = (Vector6d() << 0.1, -0.2, 0.3, 1.0, -0.5, 0.7).finished();
  Vector3d h0, a0;
  MeasurementJacobian<3> Hg, Ha;
  PredictGyro(x, &h0, &Hg);
  PredictAccel(x, qdd, Vector3d(0.01, -0.02, 0.03), 9.81, &a0, &Ha);
  for (int i = 0; i < kEkfStateSize; ++i) {
    EkfVector xp = x, xm = x;
    xp(i) += 1e-5;
    xm(i) -= 1e-5;
    Vector3d hp, hm, ap, am;
    MeasurementJacobian<3> unused;
    PredictGyro(xp, &hp, &unused);
    PredictGyro(xm, &hm, &unused);
    PredictAccel(xp, qdd, Vector3d(0.01, -0.02, 0.03), 9.81, &ap, &unused);
    PredictAccel(xm, qdd, Vector3d(0.01, -0.02, 0.03), 9.81, &am, &unused);
    EXPECT_LT((Hg.col(i) - (hp - hm) / 2e-5).norm(), 1e-6) << "gyro column " << i;
    EXPECT_LT((Ha.col(i) - (ap - am) / 2e-5).norm(), 1e-5) << "accel column " << i;
  }
}

// The friction-only dqdd/dqd of the process model against a full finite
// difference at the scenario's fastest speeds: the neglected Coriolis part
// is small.
TEST(EkfModels, DynamicsVelocityJacobianApproximation) {
  const StackConfig& c = EstimatorTestConfig();
  Vector6d q = c.home_pose, qd;
  q(0) = 0.05;
  qd << 0.015, 0.015, 0.01, 0.01, 0.01, 0.01;
  const Vector6d F = (Vector6d() << 3, 3, 3, 3, 3, 3).finished();
  Vector6d qdd;
  Matrix6d A, B;
  DynamicsAccelerationJacobians(c.platform, c.actuators.viscous_friction_nspm, q, qd, F, &qdd, &A,
                                &B);
  Matrix6d B_fd;
  for (int i = 0; i < 6; ++i) {
    Vector6d p = qd, m = qd;
    p(i) += 1e-6;
    m(i) -= 1e-6;
    B_fd.col(i) = (DynamicsAcceleration(c.platform, c.actuators.viscous_friction_nspm, q, p, F) -
                   DynamicsAcceleration(c.platform, c.actuators.viscous_friction_nspm, q, m, F)) /
                  2e-6;
  }
  EXPECT_LT((B - B_fd).norm(), 0.1 * B_fd.norm());
  EXPECT_LT(
      (qdd - DynamicsAcceleration(c.platform, c.actuators.viscous_friction_nspm, q, qd, F)).norm(),
      1e-12);
}

TEST(EkfEvents, EveryEventHasADistinctName) {
  std::set<std::string> names;
  for (uint32_t bit = 1; bit <= kEventLast; bit <<= 1) {
    names.insert(EkfEventName(static_cast<EkfEvent>(bit)));
  }
  EXPECT_EQ(names.size(), 19u);
  EXPECT_FALSE(IsRejection(kEventPoseReopened));
  EXPECT_FALSE(IsRejection(kEventRatesReopened));
  EXPECT_FALSE(IsRejection(kEventLegsHeld));
  EXPECT_FALSE(IsRejection(kEventDisturbanceJump));
  EXPECT_EQ(names.count("unknown"), 0u);
  EXPECT_TRUE(IsRejection(kGateLegs));
  EXPECT_FALSE(IsRejection(kEventDiverged));
}

}  // namespace
}  // namespace stewart::test
