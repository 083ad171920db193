#include "ekf_harness.h"

#include "stewart/config/default_config.h"

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

}  // namespace stewart::test
