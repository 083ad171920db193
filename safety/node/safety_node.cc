#include "safety_node.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <random>

#include "stewart/node/node_loop.h"
#include "stewart/node/signal_messages.h"
#include "stewart/safety/diagnostics_lcm.h"

namespace stewart {
namespace {

using safety::OperatorCommand;
using safety::SupervisorState;

int64_t NewSessionId() {
  std::random_device device;
  std::uniform_int_distribution<int64_t> id(1, INT64_MAX);
  return id(device);
}

constexpr int64_t kAnnounceStackUs = 100'000;
constexpr int64_t kAnnounceWallUs = 500'000;

}  // namespace

SafetyNode::SafetyNode(const StackConfig& config, lcm::LCM* lcm,
                       safety::ReferenceQpSolver* reference)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      health_("safety", config.lcm.channels.health, config.lcm.health_rate_hz),
      process_(config.platform, config.safety, config.actuators, config.supervisor, reference,
               &health_, config.lcm.time_plausibility),
      auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      monitor_(config.supervisor.required_processes,
               std::llround(config.supervisor.heartbeat_timeout_s * 1e6)),
      session_id_(NewSessionId()),
      operator_check_(std::llround(config.supervisor.operator_time_window_s * 1e6)) {
  receiver_.Subscribe(config.lcm.channels.state_estimate, &SafetyNode::OnState, this);
  receiver_.Subscribe(config.lcm.channels.command_nominal, &SafetyNode::OnNominal, this);
  receiver_.Subscribe(config.lcm.channels.operator_command, &SafetyNode::OnOperator, this);
  receiver_.Subscribe(config.lcm.channels.health, &SafetyNode::OnHealth, this);
  last_operator_wall_us_ = ReceiveClockUs();
}

void SafetyNode::HoldIfStalled(const lcm::ReceiveBuffer* rbuf) {
  // Stopped (SIGSTOP, a debugger, a starved CPU) and continued, this process
  // reads a backlog while its heartbeat monitor has not yet heard what came
  // meanwhile: it holds before it answers any of it. A nominal too: the
  // state it completes may have been read before the stop.
  if (rbuf->recv_utime <= 0) return;
  const std::string stalled =
      process_.supervisor().InputWaitFault(ReceiveClockUs() - rbuf->recv_utime);
  if (!stalled.empty()) Fault(stalled);
}

void SafetyNode::OnState(const lcm::ReceiveBuffer* rbuf, const std::string&, const state_t* msg) {
  HoldIfStalled(rbuf);
  safety::SafetyOutput out;
  if (process_.OnState(FromMessage(*msg), &out, rbuf->recv_utime)) Publish(out);
}

void SafetyNode::OnNominal(const lcm::ReceiveBuffer* rbuf, const std::string&,
                           const force_command_t* msg) {
  HoldIfStalled(rbuf);
  safety::SafetyOutput out;
  if (process_.OnNominal(FromMessage(*msg), &out, rbuf->recv_utime)) Publish(out);
}

void SafetyNode::OnOperator(const lcm::ReceiveBuffer*, const std::string&,
                            const operator_command_t* msg) {
  health_.CountIn();
  const auto reject = [this](const char* counter, const std::string& why) {
    ++operator_rejected_;
    health_.Reject(counter, why);
    spdlog::warn("safety: operator command rejected: {}", why);
  };
  // Who sent it and when, before what it asks: the actuators' rule (MAC,
  // wall-clock window, seq per console).
  const int64_t now_us = ReceiveClockUs();
  const OperatorVerdict verdict =
      operator_check_.Check(msg->operator_id, msg->seq, msg->utime, auth_.Verify(*msg), now_us);
  if (verdict != OperatorVerdict::kAccepted) {
    return reject(ToString(verdict), "operator command from " + std::to_string(msg->operator_id) +
                                         ", seq " + std::to_string(msg->seq) + ", " +
                                         std::to_string((msg->utime - now_us) / 1000) +
                                         " ms from this host's clock");
  }
  last_operator_wall_us_ = now_us;
  deadman_reported_ = false;
  if (msg->command < static_cast<int8_t>(OperatorCommand::kArm) ||
      msg->command > static_cast<int8_t>(OperatorCommand::kHeartbeat)) {
    return reject("operator_unknown", "unknown operator command " + std::to_string(msg->command));
  }
  const auto command = static_cast<OperatorCommand>(msg->command);
  std::string why_not;
  const bool healthy = monitor_.Healthy(now_us, &why_not);
  std::string rejection;
  last_operator_id_ = msg->operator_id;
  last_operator_seq_ = msg->seq;
  if (process_.supervisor().OnOperator(command, healthy, why_not, &rejection)) {
    ++operator_accepted_;
    last_operator_reply_.clear();
    if (command != OperatorCommand::kHeartbeat) {
      spdlog::info("safety: operator {}{}: {}", safety::ToString(command),
                   msg->note.empty() ? "" : " (" + msg->note + ")",
                   safety::ToString(process_.supervisor().state()));
    }
  } else {
    last_operator_reply_ = rejection;
    reject("operator_refused", rejection);
  }
  MaybeAnnounce(true);
}

void SafetyNode::OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
  const std::string fault = monitor_.OnHeartbeat(msg->name, msg->state, msg->seq, ReceiveClockUs());
  if (!fault.empty()) Fault(fault);
}

void SafetyNode::Fault(const std::string& reason) {
  const SupervisorState before = process_.supervisor().state();
  process_.supervisor().OnFault(reason);
  health_.Count("supervisor_faults");
  spdlog::warn("safety: {} ({} -> {})", reason, safety::ToString(before),
               safety::ToString(process_.supervisor().state()));
  MaybeAnnounce(true);
}

void SafetyNode::Periodic() {
  const int64_t now_us = ReceiveClockUs();
  const SupervisorState s = process_.supervisor().state();
  monitor_.SetMoving(s == SupervisorState::kArming || s == SupervisorState::kArmed, now_us);
  for (const std::string& fault : monitor_.CheckSilence(now_us)) Fault(fault);
  const double deadman_s = config_.supervisor.operator_timeout_s;
  if (deadman_s > 0.0 && !deadman_reported_ &&
      (s == SupervisorState::kArming || s == SupervisorState::kArmed) &&
      now_us - last_operator_wall_us_ > std::llround(deadman_s * 1e6)) {
    deadman_reported_ = true;
    Fault("operator heartbeat lost (dead-man)");
  }
  MaybeAnnounce(false);
}

void SafetyNode::MaybeAnnounce(bool force) {
  const safety::Supervisor& sup = process_.supervisor();
  const int64_t now_us = ReceiveClockUs();
  const bool changed =
      sup.state() != announced_state_ || sup.transitions() != announced_transitions_;
  const bool due = announced_utime_ < 0 || sup.utime() - announced_utime_ >= kAnnounceStackUs ||
                   now_us - announced_wall_us_ >= kAnnounceWallUs;
  if (!force && !changed && !due) return;
  supervisor_state_t& m = supervisor_msg_;
  m.utime = std::max<int64_t>(sup.utime(), 0);
  m.seq = announce_seq_++;
  m.sample_utime = sup.sample_utime();
  m.session_id = session_id_;
  m.state = static_cast<int8_t>(sup.state());
  m.arming_progress = sup.blend();
  m.motion_time_us = sup.motion_time_us();
  m.transitions = sup.transitions();
  m.operator_commands_accepted = operator_accepted_;
  m.operator_commands_rejected = operator_rejected_;
  m.reason = sup.reason();
  m.fault_latched = sup.fault_latched() ? 1 : 0;
  m.last_operator_id = last_operator_id_;
  m.last_operator_seq = last_operator_seq_;
  m.last_operator_reply = last_operator_reply_;
  m.node_faults = sup.faults_received();
  m.last_node_fault = sup.last_fault_received();
  auth_.Sign(&m);
  lcm_->publish(config_.lcm.channels.supervisor, &m);
  health_.CountOut();
  if (changed) {
    spdlog::info("safety: supervisor {} ({})", safety::ToString(sup.state()), sup.reason());
  }
  announced_utime_ = sup.utime();
  announced_wall_us_ = now_us;
  announced_state_ = sup.state();
  announced_transitions_ = sup.transitions();
  health_.SetCounter("supervisor_state", static_cast<int64_t>(sup.state()));
}

void SafetyNode::Publish(const safety::SafetyOutput& out) {
  // The actuators adopt a session from its announcement: it goes first.
  MaybeAnnounce(false);
  ToMessage(out.command, &command_);
  command_.session_id = session_id_;
  auth_.Sign(&command_);
  if (!loss_.Drops(config_.lcm.channels.command_safe, command_.seq)) {
    lcm_->publish(config_.lcm.channels.command_safe, &command_);
  }
  safety::FillDiagnosticsMessage(process_.filter(), out, &diagnostics_msg_);
  lcm_->publish(config_.lcm.channels.safety_diagnostics, &diagnostics_msg_);
}

ExitCode SafetyNode::Run() {
  spdlog::info("safety: session {:016x}, supervisor {}{}{}", session_id_,
               safety::ToString(process_.supervisor().state()),
               config_.supervisor.auto_arm ? ", arms automatically (simulation)" : "",
               auth_.enabled() ? ", authenticated channels" : "");
  MaybeAnnounce(true);
  return RunNodeLoop("safety", lcm_, &receiver_, &health_, 50, [this] {
    Periodic();
    return false;
  });
}

}  // namespace stewart
