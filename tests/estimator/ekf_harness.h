#pragma once
// Runs the EKF over the scenario truth, one update per 1 kHz sample, the way
// the process does (command of the previous sample, then the new sample).
#include <functional>

#include "scenario_truth.h"
#include "stewart/estimator/ekf.h"

namespace stewart::test {

struct RunStats {
  RmsAccumulator q_err;
  RmsAccumulator qd_err;
  Vector3d final_bias_error = Vector3d::Zero();
  int samples = 0;
  int with_estimate = 0;
  int event_counts[32] = {};
  int Count(EkfEvent e) const;
};

/// Hook per sample: may edit the sample before the update (outlier and NaN
/// injection), sees the EKF after it. Errors are accumulated for t >= settle_s.
struct RunHooks {
  std::function<void(int k, SensorSample*)> before;
  /// May edit the command the EKF is told was applied before sample k (the
  /// truth applied the unedited one): a model error.
  std::function<void(int k, Vector6d* force_n)> command;
  std::function<void(int k, const Ekf&, const TruthSample&, const UpdateResult&)> after;
};

RunStats RunScenario(const StackConfig& config, unsigned seed, double t_end_s, double settle_s,
                     Ekf* ekf, const RunHooks& hooks = {},
                     const TruthDisturbance& disturbance = {});

const StackConfig& EstimatorTestConfig();

/// The EKF the estimator process builds from `c`, started at its home pose.
Ekf MakeEkf(const StackConfig& c);

/// The noiseless reading of the state (q, qd, qdd) at 1 kHz sample `k`
/// (utime 1 s + k ms): leg lengths, the IMU's specific force and the body
/// rates with the config's gyro bias.
SensorSample NoiselessSample(const StackConfig& c, int k, bool drive_off, const Vector6d& q,
                             const Vector6d& qd, const Vector6d& qdd);

}  // namespace stewart::test
