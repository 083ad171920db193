#pragma once
// Ground truth and noisy sensor readings along the paper's scenario (NOTES.md,
// Section V.A), for the estimator tests. The motion is analytic (q, qd, qdd
// exact), the applied leg forces follow from the model's InverseDynamics, and
// the readings come from plant_sim's SensorModel (seeded noise, biases, the
// 10-bit ADC), the simulator's own sensor equations.
#include <cstdint>
#include <random>

#include "stewart/config/stack_config.h"
#include "stewart/estimator/ekf_types.h"
#include "stewart/plant_sim/sensor_model.h"

namespace stewart::test {

struct TruthState {
  Vector6d q = Vector6d::Zero();
  Vector6d qd = Vector6d::Zero();
  Vector6d qdd = Vector6d::Zero();
};

/// Random disturbances of the truth, matching the EKF's noise models so its
/// consistency can be checked exactly: a white generalised-force disturbance
/// (as an acceleration, constant over one sample, like the filter's process
/// noise) and a random-walk gyro bias. Zero: the analytic motion exactly.
struct TruthDisturbance {
  double accel_std_mps2 = 0.0;
  double angaccel_std_radps2 = 0.0;
  double gyro_bias_walk_radps_per_sqrt_s = 0.0;
};

/// One sample of the truth: the state at utime, the command applied from
/// utime to the next sample, and the sensors' readings at utime.
struct TruthSample {
  int64_t utime = 0;
  TruthState state;
  Vector6d force_n = Vector6d::Zero();
  Vector3d gyro_bias_radps = Vector3d::Zero();
  SensorSample sensors;
};

class ScenarioTruth {
 public:
  /// `angular_motion`: adds small (<= 15 mrad) smooth rotations so the
  /// rotational states are exercised (the paper holds them at zero).
  ScenarioTruth(const StackConfig& config, unsigned seed, bool angular_motion = true,
                const TruthDisturbance& disturbance = {});

  /// Analytic (undisturbed) state at time t (s).
  TruthState AnalyticState(double t_s) const;
  /// The next sample (the first one at utime 0), at the sensor rate.
  TruthSample Next();

  /// Total duration of the scenario's moves (s).
  static constexpr double kDurationS = 54.0;

 private:
  SensorSample Sense(int64_t utime, const TruthState& s);

  StackConfig config_;
  bool angular_motion_;
  TruthDisturbance disturbance_;
  int64_t period_us_;
  int64_t next_utime_ = 0;
  // Disturbance part of the state: q = analytic + d, qd = analytic + dd.
  Vector6d d_ = Vector6d::Zero();
  Vector6d dd_ = Vector6d::Zero();
  Vector3d gyro_bias_radps_;
  SensorModel sensor_model_;
  std::mt19937 rng_;  // the disturbances
  std::normal_distribution<double> normal_{0.0, 1.0};
};

/// Root-mean-square helper over samples of an error vector.
struct RmsAccumulator {
  Vector6d sum_sq = Vector6d::Zero();
  int n = 0;
  void Add(const Vector6d& e) {
    sum_sq += e.cwiseProduct(e);
    ++n;
  }
  Vector6d Rms() const { return (sum_sq / std::max(n, 1)).cwiseSqrt(); }
};

}  // namespace stewart::test
