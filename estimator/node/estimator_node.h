#pragma once
// The `estimator` process: one EKF update per sensor_t on channels.sensors,
// the safe force command (channels.command_safe) as the process model's
// input, state_t on channels.state_estimate. Optional perfect-state mode
// republishes channels.state_truth instead (testing only).
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {

class EstimatorNode {
 public:
  EstimatorNode(const StackConfig& config, lcm::LCM* lcm, bool perfect_state);

  /// Handles messages until a stop signal; returns the exit status.
  ExitCode Run();

  void OnSensor(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const sensor_t* msg);
  void OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                 const force_command_t* msg);
  void OnTruth(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const state_t* msg);

  HealthReporter& health() { return health_; }

 private:
  void Publish(const state_t& msg);

  StackConfig config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  bool perfect_state_;
  Ekf ekf_;
  HealthReporter health_;
  int64_t seq_ = 0;
};

}  // namespace stewart
