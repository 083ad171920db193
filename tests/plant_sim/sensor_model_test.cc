// Sensor noise statistics, bias, quantisation and reproducibility.
#include "stewart/plant_sim/sensor_model.h"

#include <gtest/gtest.h>

#include <cmath>

#include "plant_test_util.h"
#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

using test::Config;

struct Moments {
  Eigen::VectorXd mean, std;
};

// Statistics of (reading - truth) over n samples at one moving state.
template <typename Extract>
Moments ErrorMoments(SensorModel* sensors, int n, int dim, Extract extract) {
  const Vector6d q = Config().plant_sim.initial_pose + Vector6d::Constant(0.01);
  Vector6d qd;
  qd << 0.01, -0.02, 0.03, 0.1, -0.2, 0.3;
  Vector6d qdd;
  qdd << 0.5, -0.3, 0.2, 1.0, -2.0, 0.5;
  const Vector6d l = InverseKinematics(Config().platform, q);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(dim), sum2 = Eigen::VectorXd::Zero(dim);
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd e = extract(sensors->Sample(q, qd, qdd, l), q, qd, qdd, l);
    sum += e;
    sum2 += e.cwiseProduct(e);
  }
  Moments m;
  m.mean = sum / n;
  m.std = (sum2 / n - m.mean.cwiseProduct(m.mean)).cwiseSqrt();
  return m;
}

TEST(SensorModel, NoiseAndBiasMatchConfig) {
  SensorConfig cfg = Config().sensors;
  cfg.leg_adc_bits = 0;  // the ADC's own error is tested below
  cfg.has_orientation = true;
  const double g = Config().platform.gravity_mps2;
  const int n = 40000;
  // Mean within 5 standard errors; std within 5 % (std error of a std
  // estimate is sigma / sqrt(2n) = 0.35 % here).
  auto check = [&](const Moments& m, const Eigen::VectorXd& bias, double sigma) {
    for (int i = 0; i < m.mean.size(); ++i) {
      EXPECT_NEAR(m.mean(i), bias(i), 5.0 * sigma / std::sqrt(n)) << i;
      EXPECT_NEAR(m.std(i), sigma, 0.05 * sigma) << i;
    }
  };
  SensorModel legs(cfg, Config().actuators, g);
  check(ErrorMoments(&legs, n, 6,
                     [](const SensorReading& r, auto&, auto&, auto&, const Vector6d& l) {
                       return Eigen::VectorXd(r.leg_length_m - l);
                     }),
        Eigen::VectorXd::Zero(6), cfg.leg_pot_noise_std_m);
  SensorModel gyro(cfg, Config().actuators, g);
  check(
      ErrorMoments(&gyro, n, 3,
                   [](const SensorReading& r, const Vector6d& q, const Vector6d& qd, auto&, auto&) {
                     return Eigen::VectorXd(r.gyro_radps - BodyAngularVelocity(q, qd));
                   }),
      cfg.gyro_bias_radps, cfg.gyro_noise_std_radps);
  SensorModel accel(cfg, Config().actuators, g);
  check(ErrorMoments(&accel, n, 3,
                     [&](const SensorReading& r, const Vector6d& q, const Vector6d& qd,
                         const Vector6d& qdd, auto&) {
                       return Eigen::VectorXd(
                           r.accel_mps2 - ImuSpecificForce(q, qd, qdd, cfg.imu_offset_in_P_m, g));
                     }),
        cfg.accel_bias_mps2, cfg.accel_noise_std_mps2);
  SensorModel orient(cfg, Config().actuators, g);
  check(ErrorMoments(&orient, n, 3,
                     [](const SensorReading& r, const Vector6d& q, auto&, auto&, auto&) {
                       return Eigen::VectorXd(r.orientation_rpy_rad - q.tail<3>());
                     }),
        Eigen::VectorXd::Zero(3), cfg.orientation_noise_std_rad);
}

TEST(SensorModel, LegAdcQuantisesOverTheStroke) {
  SensorConfig cfg = Config().sensors;
  const ActuatorConfig& a = Config().actuators;
  cfg.leg_adc_bits = 10;
  const double lsb = LegAdcResolution(cfg, a);
  EXPECT_NEAR(lsb, a.stroke_m / 1023.0, 1e-15);
  Vector6d l;
  l << a.min_length_m - 0.01, a.min_length_m, a.min_length_m + 0.4 * lsb,
      a.min_length_m + 0.6 * lsb, a.min_length_m + a.stroke_m, a.min_length_m + a.stroke_m + 0.01;
  const Vector6d out = QuantiseLegLength(cfg, a, l);
  EXPECT_DOUBLE_EQ(out(0), a.min_length_m);  // saturates below
  EXPECT_DOUBLE_EQ(out(1), a.min_length_m);
  EXPECT_DOUBLE_EQ(out(2), a.min_length_m);
  EXPECT_NEAR(out(3), a.min_length_m + lsb, 1e-15);
  EXPECT_NEAR(out(4), a.min_length_m + a.stroke_m, 1e-12);
  EXPECT_NEAR(out(5), a.min_length_m + a.stroke_m, 1e-12);  // saturates above
  // Every reading of the default sensors lies on the ADC grid.
  SensorModel sensors(Config().sensors, a, Config().platform.gravity_mps2);
  const Vector6d q = Config().plant_sim.initial_pose;
  const Vector6d lt = InverseKinematics(Config().platform, q);
  for (int k = 0; k < 100; ++k) {
    const Vector6d r = sensors.Sample(q, Vector6d::Zero(), Vector6d::Zero(), lt).leg_length_m;
    for (int i = 0; i < kNumLegs; ++i) {
      const double code = (r(i) - a.min_length_m) / lsb;
      EXPECT_NEAR(code, std::round(code), 1e-6);
      EXPECT_LE(std::abs(r(i) - lt(i)), lsb / 2 + 6 * cfg.leg_pot_noise_std_m);
    }
  }
}

TEST(SensorModel, SeedGivesOneSequence) {
  const auto& c = Config();
  const Vector6d q = c.plant_sim.initial_pose;
  const Vector6d l = InverseKinematics(c.platform, q);
  SensorModel a(c.sensors, c.actuators, 9.81), b(c.sensors, c.actuators, 9.81);
  SensorConfig other = c.sensors;
  other.seed += 1;
  SensorModel d(other, c.actuators, 9.81);
  bool differs = false;
  for (int k = 0; k < 50; ++k) {
    const SensorReading ra = a.Sample(q, Vector6d::Zero(), Vector6d::Zero(), l);
    const SensorReading rb = b.Sample(q, Vector6d::Zero(), Vector6d::Zero(), l);
    const SensorReading rd = d.Sample(q, Vector6d::Zero(), Vector6d::Zero(), l);
    EXPECT_EQ(ra.gyro_radps, rb.gyro_radps);
    EXPECT_EQ(ra.accel_mps2, rb.accel_mps2);
    EXPECT_EQ(ra.leg_length_m, rb.leg_length_m);
    differs = differs || ra.gyro_radps != rd.gyro_radps;
  }
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace stewart
