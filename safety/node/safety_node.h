#pragma once
// The safety process on LCM: state estimate + nominal command in, safe
// command and diagnostics out. Every decision is SafetyProcess's
// (safety/include/stewart/safety/safety_process.h); this class subscribes,
// converts and publishes.
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/safety/safety_process.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {

class SafetyNode {
 public:
  SafetyNode(const StackConfig& config, lcm::LCM* lcm, safety::ReferenceQpSolver* reference);

  /// Handles LCM traffic until a stop signal.
  ExitCode Run();

  void OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg);
  void OnNominal(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg);

 private:
  void Publish(const safety::SafetyOutput& out);

  const StackConfig& config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  HealthReporter health_;
  safety::SafetyProcess process_;
  force_command_t command_{};
  safety_diagnostics_t diagnostics_msg_{};
};

}  // namespace stewart
