#include "ekf_harness.h"

#include "stewart/config/default_config.h"
#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"

namespace stewart::test {

int RunStats::Count(EkfEvent e) const {
  for (int b = 0; b < 32; ++b) {
    if ((1u << b) == static_cast<uint32_t>(e)) return event_counts[b];
  }
  return 0;
}

// The shipped config, except that the scenario truth applies each command
// from its own sample on: no actuator latency to model.
const StackConfig& EstimatorTestConfig() {
  static const StackConfig config = [] {
    StackConfig c = DefaultStackConfig();
    c.estimator.command_latency_s = 0.0;
    return c;
  }();
  return config;
}

Ekf MakeEkf(const StackConfig& c) {
  return Ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
}

RunStats RunScenario(const StackConfig& config, unsigned seed, double t_end_s, double settle_s,
                     Ekf* ekf, const RunHooks& hooks, const TruthDisturbance& disturbance) {
  ScenarioTruth truth(config, seed, true, disturbance);
  RunStats stats;
  TruthSample previous;
  for (int k = 0;; ++k) {
    TruthSample now = truth.Next();
    const double t_s = static_cast<double>(now.utime) * 1e-6;
    if (t_s > t_end_s) break;
    if (k > 0) {
      Vector6d told_n = previous.force_n;
      if (hooks.command) hooks.command(k, &told_n);
      ekf->SetForceCommand(previous.utime, told_n);
    }
    SensorSample sample = now.sensors;
    if (hooks.before) hooks.before(k, &sample);
    const UpdateResult result = ekf->Update(sample);
    ++stats.samples;
    for (int b = 0; b < 32; ++b) {
      if (result.events & (1u << b)) ++stats.event_counts[b];
    }
    if (hooks.after) hooks.after(k, *ekf, now, result);
    if (result.has_estimate && t_s >= settle_s) {
      ++stats.with_estimate;
      const Estimate e = ekf->estimate();
      stats.q_err.Add(e.q - now.state.q);
      stats.qd_err.Add(e.qd - now.state.qd);
      stats.final_bias_error = e.gyro_bias_radps - now.gyro_bias_radps;
    }
    previous = now;
  }
  return stats;
}

SensorSample NoiselessSample(const StackConfig& c, int k, bool drive_off, const Vector6d& q,
                             const Vector6d& qd, const Vector6d& qdd) {
  SensorSample s;
  s.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
  s.drive_off = drive_off;
  s.leg_length_m = InverseKinematics(c.platform, q);
  s.accel_mps2 = ImuSpecificForce(q, qd, qdd, c.sensors.imu_offset_in_P_m, c.platform.gravity_mps2);
  s.gyro_radps = BodyAngularVelocity(q, qd) + c.sensors.gyro_bias_radps;
  return s;
}

}  // namespace stewart::test
