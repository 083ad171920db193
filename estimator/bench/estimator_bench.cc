// Time per EKF update (predict + leg, gyro and accelerometer corrections) at
// a moving state, for both process models; and with a command that changes
// every sample (the latency allowance's noise then acts every update).
#include <benchmark/benchmark.h>

#include <cmath>

#include "stewart/config/config_loader.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"

namespace {

void BM_EkfUpdate(benchmark::State& state, stewart::EstimatorProcessModel model,
                  bool changing_command = false) {
  using namespace stewart;
  StackConfig c = LoadStackConfig(DefaultConfigPath());
  c.estimator.process_model = model;
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  Vector6d q = c.home_pose;
  Vector6d qd;
  qd << 0.01, -0.005, 0.004, 0.01, -0.02, 0.015;
  const Vector6d qdd = Vector6d::Zero();
  const Vector6d force = InverseDynamics(EvaluateDynamics(c.platform, q, qd), qdd);
  SensorSample s;
  s.leg_length_m = InverseKinematics(c.platform, q);
  s.gyro_radps = BodyAngularVelocity(q, qd);
  s.accel_mps2 = ImuSpecificForce(q, qd, qdd, c.sensors.imu_offset_in_P_m, c.platform.gravity_mps2);
  EkfVector std = EkfVector::Constant(1e-3);
  ekf.Initialize(0, q, qd, std);
  int64_t utime = 0;
  for (auto _ : state) {
    utime += 1000;
    // +-0.05 N per leg about the hover force, alternating.
    const double dither_n = changing_command ? ((utime / 1000) % 2 == 0 ? 0.05 : -0.05) : 0.0;
    ekf.SetForceCommand(utime - 1000, force + Vector6d::Constant(dither_n));
    s.utime = utime;
    benchmark::DoNotOptimize(ekf.Update(s));
    // Keep the filter near the (stationary) readings: re-seed occasionally
    // so the state cannot drift out of the benchmark's regime.
    if ((utime / 1000) % 4096 == 0) ekf.Initialize(utime, q, qd, std);
  }
}

BENCHMARK_CAPTURE(BM_EkfUpdate, dynamics, stewart::EstimatorProcessModel::kDynamics);
BENCHMARK_CAPTURE(BM_EkfUpdate, dynamics_changing_command,
                  stewart::EstimatorProcessModel::kDynamics, true);
BENCHMARK_CAPTURE(BM_EkfUpdate, constant_velocity,
                  stewart::EstimatorProcessModel::kConstantVelocity);

}  // namespace

BENCHMARK_MAIN();
