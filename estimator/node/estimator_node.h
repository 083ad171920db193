#pragma once
// The estimator process on LCM: sensor_t on channels.sensors and the safe
// command (channels.command_safe, the process model's input) in, state_t on
// channels.state_estimate out; in perfect-state mode channels.state_truth is
// republished instead (testing only). The safety session's announcements
// (channels.supervisor) decide, as in the actuators, which safe commands are
// believed. Every decision is EstimatorProcess's; this class subscribes,
// verifies MACs, converts and publishes.
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/estimator/estimator_process.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/node/test_loss.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {

class EstimatorNode {
 public:
  EstimatorNode(const StackConfig& config, lcm::LCM* lcm, bool perfect_state);

  /// Handles messages until a stop signal.
  ExitCode Run();

  void OnSensor(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const sensor_t* msg);
  void OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                 const force_command_t* msg);
  void OnTruth(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const state_t* msg);
  void OnSupervisor(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                    const supervisor_state_t* msg);

  HealthReporter& health() { return health_; }
  /// Testing only: the estimate numbered `seq` is lost on its way (TestLoss).
  void LoseEstimateForTest(int64_t seq) { loss_.Lose(config_.lcm.channels.state_estimate, seq); }

 private:
  void Publish(const StateSample& state);

  StackConfig config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  HealthReporter health_;
  MessageAuthenticator auth_;
  EstimatorProcess process_;
  state_t state_msg_{};
  TestLoss loss_;
};

}  // namespace stewart
