#include "bridge_node.h"

#include <poll.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "stewart/guard/guard_limits.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/operator_reset.h"
#include "stewart/node/signal_messages.h"
#include "stewart/node/stop_signal.h"
#include "stewart/sensor_t.hpp"

namespace stewart {
namespace {

int64_t WallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int8_t HealthState(hw::LinkState state) {
  switch (state) {
    case hw::LinkState::kStarting:
      return health_t::STATE_STARTING;
    case hw::LinkState::kOk:
      return health_t::STATE_OK;
    case hw::LinkState::kDegraded:
      return health_t::STATE_DEGRADED;
    case hw::LinkState::kFault:
      return health_t::STATE_FAULT;
  }
  return health_t::STATE_FAULT;
}

}  // namespace

BridgeNode::BridgeNode(const StackConfig& config, lcm::LCM* lcm, hw::Transport* transport,
                       const hw::BringupOptions& bringup)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      transport_(transport),
      bridge_(config.hw_bridge, config.platform.leg_min_length_m,
              config.platform.leg_max_length_m - config.platform.leg_min_length_m,
              config.actuators.force_limit_n, bringup, config.guard),
      auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      operator_check_(SecondsToMicros(config.supervisor.operator_time_window_s)),
      health_("hw_bridge", config.lcm.channels.health, config.lcm.health_rate_hz),
      reader_(transport->datagram()) {
  spdlog::info("hw_bridge: link session {} (zero drive until the device follows it)",
               bridge_.link_session());
  receiver_.Subscribe(config.lcm.channels.supervisor, &BridgeNode::OnSupervisor, this);
  receiver_.Subscribe(config.lcm.channels.operator_command, &BridgeNode::OnOperator, this);
  spdlog::info(
      "hw_bridge: commands accepted from the safety session announced on {}{}",
      config.lcm.channels.supervisor,
      auth_.enabled() ? ", authenticated (lcm.auth_key_file)" : ", no key: not authenticated");
  // In bring-up the safe commands are still heard, to be rejected and
  // counted (wrong_mode_command): a filter running then is a mistake to see.
  receiver_.Subscribe(config.lcm.channels.command_safe, &BridgeNode::OnCommand, this);
  if (bringup.enabled) {
    receiver_.Subscribe(
        hw::BringupDutyChannel(config.lcm.channel_prefix, config.lcm.channel_suffix),
        &BridgeNode::OnDutyCommand, this);
    applied_channel_ =
        hw::BringupAppliedChannel(config.lcm.channel_prefix, config.lcm.channel_suffix);
  }
}

ExitCode BridgeNode::Run() {
  std::array<pollfd, 2> fds{pollfd{transport_->fd(), POLLIN, 0}, pollfd{receiver_.fd(), POLLIN, 0}};
  while (!StopRequested()) {
    const int ready = poll(fds.data(), fds.size(), 5);
    if (ready > 0 && (fds[0].revents & (POLLIN | POLLERR | POLLHUP)) != 0) ReadDevice();
    if (ready > 0 && (fds[1].revents & POLLIN) != 0) receiver_.HandleTimeout(0);
    UpdateHealth();
  }
  health_.SetState(health_t::STATE_STOPPED);
  health_.MaybePublish(lcm_, true);
  return ExitCode::kOk;
}

void BridgeNode::ReadDevice() {
  for (int i = 0; i < 64; ++i) {
    const long n = transport_->Receive(rx_.data(), rx_.size(), 0);
    if (n == 0) return;
    if (n < 0) {
      health_.Count("transport_errors");
      return;
    }
    reader_.Feed(
        rx_.data(), static_cast<std::size_t>(n), rx_.size(),
        [this](const hw::DecodedFrame& f) { OnFrame(f); },
        [this](hw::DecodeStatus s) { health_.Reject("corrupt_frame", ToString(s)); });
  }
}

void BridgeNode::OnFrame(const hw::DecodedFrame& frame) {
  hw::SensorSample sample;
  const uint32_t device_session_was = bridge_.device_session();
  const hw::FrameOutcome outcome = bridge_.OnFrame(frame, clock_.NowMicros(), &sample);
  if (bridge_.device_session() != device_session_was) {
    if (bridge_.device_session() == bridge_.link_session()) {
      spdlog::info("hw_bridge: the device follows link session {}", bridge_.link_session());
    } else {
      spdlog::warn(
          "hw_bridge: the device follows link session {}, not this bridge's {}: zero drive",
          bridge_.device_session(), bridge_.link_session());
    }
  }
  if (outcome == hw::FrameOutcome::kUnexpectedType) {
    health_.Reject("unexpected_frame_type");
    return;
  }
  health_.CountIn();
  if (outcome != hw::FrameOutcome::kPublish) return;
  sensor_t msg{};
  msg.utime = sample.utime;
  msg.seq = sample.seq;
  msg.sample_utime = sample.utime;
  ToArray(sample.leg_length_m, msg.leg_length_m);
  ToArray(sample.gyro_radps, msg.gyro_radps);
  ToArray(sample.accel_mps2, msg.accel_mps2);
  msg.has_orientation = false;
  msg.status = sample.status;
  lcm_->publish(config_.lcm.channels.sensors, &msg);
  health_.CountOut();
  health_.SetStackTime(sample.utime, sample.utime);
  if (bridge_.bringup()) PublishApplied();
  if (bridge_.TickFrameDue()) SendCommand();
}

void BridgeNode::PublishApplied() {
  const hw::AppliedDuty& applied = bridge_.applied();
  duty_command_t msg{};
  msg.utime = applied.since_utime;
  msg.seq = applied_seq_++;
  msg.sample_utime = applied.sample_utime;
  ToArray(applied.duty, msg.duty);
  msg.guard_mask = applied.guard_mask;
  msg.flags =
      (applied.device_watchdog ? duty_command_t::FLAG_DEVICE_WATCHDOG : 0) |
      (bridge_.last_reason() != hw::DriveReason::kCommand ? duty_command_t::FLAG_ZERO_DRIVE : 0);
  lcm_->publish(applied_channel_, &msg);
}

void BridgeNode::OnDutyCommand(const lcm::ReceiveBuffer*, const std::string&,
                               const duty_command_t* msg) {
  health_.CountIn();
  const hw::CommandVerdict verdict = bridge_.OnDutyCommand(msg->utime, FromArray(msg->duty));
  if (verdict != hw::CommandVerdict::kAccepted) health_.Reject(ToString(verdict));
  if (hw::SendsAtOnce(verdict)) SendCommand();
}

void BridgeNode::OnCommand(const lcm::ReceiveBuffer*, const std::string&,
                           const force_command_t* msg) {
  health_.CountIn();
  const hw::CommandVerdict verdict = bridge_.OnSafeCommand(FromMessage(*msg), auth_.Verify(*msg));
  if (verdict == hw::CommandVerdict::kUntrusted) {
    health_.Reject(ToString(bridge_.last_rejection()),
                   "force_command_t seq " + std::to_string(msg->seq) + ", session " +
                       std::to_string(msg->session_id) + ", sample_utime " +
                       std::to_string(msg->sample_utime) + " (following session " +
                       std::to_string(bridge_.acceptor().session_id()) + ")");
  } else if (verdict != hw::CommandVerdict::kAccepted) {
    health_.Reject(ToString(verdict));
  }
  if (hw::SendsAtOnce(verdict)) SendCommand();
}

void BridgeNode::OnSupervisor(const lcm::ReceiveBuffer*, const std::string&,
                              const supervisor_state_t* msg) {
  health_.CountIn();
  const AnnouncementVerdict v = bridge_.OnAnnouncement({msg->utime, msg->seq, msg->session_id},
                                                       auth_.Verify(*msg), clock_.NowMicros());
  if (IsRejection(v)) {
    health_.Reject(ToString(v), "supervisor_state_t session " + std::to_string(msg->session_id) +
                                    ", seq " + std::to_string(msg->seq) + ", utime " +
                                    std::to_string(msg->utime) + " (newest sample " +
                                    std::to_string(bridge_.latest_sample_utime()) + ")");
  } else if (v == AnnouncementVerdict::kAdopted) {
    spdlog::info("hw_bridge: following safety session {} (announced at utime {})", msg->session_id,
                 msg->utime);
  }
}

void BridgeNode::OnOperator(const lcm::ReceiveBuffer*, const std::string&,
                            const operator_command_t* msg) {
  // Only RESET concerns the bridge (its guard); the supervisor judges the rest.
  if (!AcceptActuatorReset(*msg, auth_.Verify(*msg), WallMicros(), &operator_check_, &health_)) {
    return;
  }
  const bool was_tripped = bridge_.actuator_guard().tripped();
  const std::string what = bridge_.actuator_guard().Describe();
  const GuardResetResult r = bridge_.OnOperatorReset();
  if (r == GuardResetResult::kCleared) {
    spdlog::warn("hw_bridge: guard cleared by operator {} (was: {})", msg->operator_id, what);
  } else if (was_tripped) {
    spdlog::warn("hw_bridge: operator RESET refused: readings not back inside ({})", what);
  }
}

void BridgeNode::SendCommand() {
  std::array<uint8_t, hw::kMaxFrameSize> frame{};
  const std::size_t size = bridge_.BuildCommandFrame(clock_.NowMicros(), frame.data());
  if (!transport_->Send(frame.data(), size)) health_.Count("send_errors");
}

void BridgeNode::UpdateHealth() {
  const hw::BridgeCounters& c = bridge_.counters();
  const hw::RxStats& rx = reader_.stats();
  ReportReceiverCounters(receiver_, &health_);
  health_.SetCounter("sensor_frames", static_cast<int64_t>(c.sensor_frames));
  health_.SetCounter("lost_frames", static_cast<int64_t>(c.lost_frames));
  health_.SetCounter("corrupt_frames", static_cast<int64_t>(rx.corrupt()));
  health_.SetCounter("late_frames", static_cast<int64_t>(c.late_frames));
  health_.SetCounter("reordered_frames", static_cast<int64_t>(c.reordered_frames));
  health_.SetCounter("stream_bytes_skipped", static_cast<int64_t>(rx.bytes_skipped));
  health_.SetCounter("rtt_us_mean", c.rtt_us.mean());
  health_.SetCounter("rtt_us_max", c.rtt_us.max);
  health_.SetCounter("rtt_samples", c.rtt_us.count);
  health_.SetCounter("delay_us_mean", c.delay_us.mean());
  health_.SetCounter("delay_us_max", c.delay_us.max);
  health_.SetCounter("command_frames", static_cast<int64_t>(c.command_frames));
  health_.SetCounter("commands_accepted", static_cast<int64_t>(c.commands_accepted));
  health_.SetCounter("zero_drive_frames", static_cast<int64_t>(c.zero_drive_frames));
  health_.SetCounter("zero_drive", bridge_.last_reason() != hw::DriveReason::kCommand ? 1 : 0);
  health_.SetCounter("force_clamped", static_cast<int64_t>(c.force_clamped));
  health_.SetCounter("duty_clamped", static_cast<int64_t>(c.duty_clamped));
  health_.SetCounter("force_deadzoned", static_cast<int64_t>(c.force_deadzoned));
  health_.SetCounter("leg_fault_samples", static_cast<int64_t>(c.leg_fault_samples));
  health_.SetCounter("imu_fault_samples", static_cast<int64_t>(c.imu_fault_samples));
  health_.SetCounter("device_watchdog_samples", static_cast<int64_t>(c.device_watchdog_samples));
  health_.SetCounter("device_rx_corrupt", static_cast<int64_t>(c.device_rx_corrupt));
  health_.SetCounter("device_rx_lost", static_cast<int64_t>(c.device_rx_lost));
  health_.SetCounter("device_rx_session_rejected",
                     static_cast<int64_t>(c.device_rx_session_rejected));
  health_.SetCounter("link_session", bridge_.link_session());
  health_.SetCounter("device_session", bridge_.device_session());
  health_.SetCounter("session_pending_frames", static_cast<int64_t>(c.session_pending_frames));
  health_.SetCounter("session_pending_samples", static_cast<int64_t>(c.session_pending_samples));
  const SafeCommandAcceptor& acceptor = bridge_.acceptor();
  const ActuatorGuard& guard = bridge_.actuator_guard();
  health_.SetCounter("safety_session", acceptor.session_id());
  health_.SetCounter("sessions_adopted", acceptor.sessions_adopted());
  health_.SetCounter("commands_trusted", acceptor.accepted());
  health_.SetCounter("applied_age_max_us", c.applied_age_max_us);
  health_.SetCounter("drive_off_frames", static_cast<int64_t>(c.drive_off_frames));
  health_.SetCounter("guard_frames", static_cast<int64_t>(c.guard_frames));
  health_.SetCounter("guard_tripped", guard.tripped() ? 1 : 0);
  health_.SetCounter("guard_resets", guard.resets_cleared());
  health_.SetCounter("guard_resets_refused", guard.resets_refused());
  // How close the run came to the guard's limits, to size them: um, um/s, mN.
  health_.SetCounter("guard_min_end_distance_um", std::llround(guard.min_end_distance_m() * 1e6));
  health_.SetCounter("guard_max_speed_umps", std::llround(guard.max_speed_mps() * 1e6));
  health_.SetCounter("guard_max_force_mn", std::llround(guard.max_force_n() * 1e3));
  if (guard.trips() != guard_trips_logged_) {
    guard_trips_logged_ = guard.trips();
    if (guard.tripped()) spdlog::error("hw_bridge: guard tripped: {}", guard.Describe());
  }
  if (!bridge_.bringup()) health_.SetCounter("guard_trips", guard.trips());
  if (bridge_.bringup()) {
    health_.SetCounter("bringup", 1);
    health_.SetCounter("guard_trips", static_cast<int64_t>(c.guard_trips));
    health_.SetCounter("guard_limited_frames", static_cast<int64_t>(c.guard_limited_frames));
    health_.SetCounter("guard_mask", bridge_.applied().guard_mask);
  }

  const hw::LinkHealth link = bridge_.Health(clock_.NowMicros(), transport_->description());
  health_.SetState(HealthState(link.state));
  health_.SetError(link.error);
  if (health_.MaybePublish(lcm_)) bridge_.ResetWindows();
}

}  // namespace stewart
