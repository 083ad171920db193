#pragma once
// The estimator process's decisions, without LCM: which commands and sensor
// samples reach the EKF, which EKF events are counted as rejections, when an
// estimate is published and with which status, and the perfect-state mode
// (ground truth republished, testing only). The node (estimator/node)
// converts messages and publishes; replay drives the same class.
#include <cstdint>

#include "stewart/common/health_counters.h"
#include "stewart/common/signals.h"
#include "stewart/estimator/ekf.h"

namespace stewart {

/// The state estimate of an EKF estimate: utime = sample_utime = the sensor
/// sample's utime; status VALID or INITIALIZING, plus DIVERGED.
StateSample StateFromEstimate(const Estimate& estimate, int64_t seq);

class EstimatorProcess {
 public:
  /// `counters` must outlive this object.
  EstimatorProcess(const PlatformParams& platform, const ActuatorConfig& actuators,
                   const SensorConfig& sensors, const EstimatorConfig& estimator,
                   const Vector6d& home_pose, HealthCounters* counters);

  /// A safe command arrived: the process model's input (non-finite ones are
  /// rejected).
  void OnCommand(const ForceCommand& command);
  /// A sensor sample arrived. Returns true when `out` holds an estimate to
  /// publish.
  bool OnSensor(const SensorSample& sample, StateSample* out);
  /// Perfect-state mode: the ground truth, republished as the estimate.
  bool OnTruth(const StateSample& truth, StateSample* out);

  const Ekf& ekf() const { return ekf_; }

 private:
  /// Publishing bookkeeping: non-finite estimates are rejected, never sent.
  bool Emit(const StateSample& state, StateSample* out);

  Ekf ekf_;
  HealthCounters* counters_;
  int64_t seq_ = 0;
};

}  // namespace stewart
