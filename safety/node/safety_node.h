#pragma once
// The safety process on LCM: state estimate + nominal command in, safe
// command and diagnostics out; the supervisor's state out, operator commands
// and the processes' heartbeats in. Every decision on commands is
// SafetyProcess's (safety/include/stewart/safety/safety_process.h) and its
// supervisor's; this class subscribes, checks who sent what, converts and
// publishes.
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/force_command_t.hpp"
#include "stewart/guard/operator_command_check.h"
#include "stewart/health_t.hpp"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/node/test_loss.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/safety/process_monitor.h"
#include "stewart/safety/safety_process.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {

class SafetyNode {
 public:
  SafetyNode(const StackConfig& config, lcm::LCM* lcm, safety::ReferenceQpSolver* reference);

  /// Handles LCM traffic until a stop signal.
  ExitCode Run();

  void OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg);
  void OnNominal(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg);
  void OnOperator(const lcm::ReceiveBuffer*, const std::string&, const operator_command_t* msg);
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg);

  int64_t session_id() const { return session_id_; }
  const safety::SafetyProcess& process() const { return process_; }
  /// Testing only: the safe command numbered `seq` is lost on its way
  /// (TestLoss); its diagnostics go out.
  void LoseCommandForTest(int64_t seq) { loss_.Lose(config_.lcm.channels.command_safe, seq); }

 private:
  void Publish(const safety::SafetyOutput& out);
  /// The supervisor's state on its channel: before the first command, on a
  /// change, and every 100 ms of stack time or 500 ms of wall time.
  void MaybeAnnounce(bool force);
  /// Wall-time duties between messages: heartbeat silence, the operator's
  /// dead-man, the periodic announcement.
  void Periodic();
  /// HOLD (a latched fault) when the input in `rbuf` waited too long to be
  /// read while the platform moves (Supervisor::InputWaitFault).
  void HoldIfStalled(const lcm::ReceiveBuffer* rbuf);
  void Fault(const std::string& reason);

  const StackConfig& config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  HealthReporter health_;
  safety::SafetyProcess process_;
  MessageAuthenticator auth_;
  safety::ProcessMonitor monitor_;
  const int64_t session_id_;
  OperatorCommandCheck operator_check_;
  force_command_t command_{};
  TestLoss loss_;
  safety_diagnostics_t diagnostics_msg_{};
  supervisor_state_t supervisor_msg_{};
  int64_t announce_seq_ = 0;
  int64_t announced_utime_ = -1;  // stack time of the last announcement
  int64_t announced_wall_us_ = 0;
  safety::SupervisorState announced_state_ = safety::SupervisorState::kDisarmed;
  int64_t announced_transitions_ = -1;
  int64_t last_operator_wall_us_ = 0;  // dead-man
  bool deadman_reported_ = false;
  int64_t operator_accepted_ = 0;
  int64_t operator_rejected_ = 0;
  int64_t last_operator_id_ = 0;
  int64_t last_operator_seq_ = 0;
  std::string last_operator_reply_;
};

}  // namespace stewart
