#pragma once
// The controller process on LCM: state estimate in, nominal force command
// (and, when following a scenario, the active setpoint) out. Every decision
// is ControllerProcess's; this class subscribes, converts and publishes.
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <optional>

#include "stewart/config/stack_config.h"
#include "stewart/controller/controller_process.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {

class ControllerNode {
 public:
  /// `restart_scenario`: the scenario starts over at t = 0 (else it takes up
  /// the supervisor's motion clock: where the platform's motion was).
  ControllerNode(const StackConfig& config, lcm::LCM* lcm, std::optional<Scenario> scenario,
                 bool exit_at_end, bool restart_scenario = false);

  /// Runs until a stop signal, or the scenario's end with exit_at_end.
  ExitCode Run();

  void OnState(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const state_t* msg);
  void OnSetpoint(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                  const setpoint_t* msg);
  void OnSupervisor(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                    const supervisor_state_t* msg);

 private:
  StackConfig config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  HealthReporter health_;
  ControllerProcess process_;
  MessageAuthenticator auth_;
  bool exit_at_end_;
  force_command_t command_{};
  setpoint_t setpoint_echo_{};
};

}  // namespace stewart
