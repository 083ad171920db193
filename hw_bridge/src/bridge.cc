#include "stewart/hw_bridge/bridge.h"

#include <algorithm>
#include <cmath>

#include "stewart/guard/guard_limits.h"
#include "stewart/hw_bridge/link_session.h"

namespace stewart::hw {
namespace {
constexpr int32_t kSensorStatusMask = 0x1F;  // DeviceStatus bits 0..4 = sensor_t.STATUS_*
}

bool SendsAtOnce(CommandVerdict verdict) {
  return verdict == CommandVerdict::kAccepted || verdict == CommandVerdict::kNonFinite;
}

HwBridge::HwBridge(const HwBridgeConfig& hw, double min_length_m, double stroke_m,
                   double force_limit_n, const BringupOptions& bringup, const GuardConfig& guard)
    : hw_(hw),
      calibration_(hw, min_length_m, stroke_m),
      imu_(hw),
      drive_map_(hw, force_limit_n),
      clock_(hw.clock_drift_ppm),
      acceptor_(AcceptorLimitsOf(guard, hw.command_timeout_s)),
      actuator_guard_(ActuatorGuardLimitsOf(guard, min_length_m, min_length_m + stroke_m)),
      bringup_(bringup),
      guard_(bringup.guard),
      link_session_(NewLinkSession()) {}

bool HwBridge::OnSensorFrame(const SensorFrame& frame, int64_t host_rx_us, SensorSample* sample) {
  if (have_sample_) {
    // Signed difference so a wrapping uint32 seq still orders correctly.
    const auto gap = static_cast<int32_t>(frame.seq - last_sample_seq_);
    if (gap <= 0) {
      ++counters_.reordered_frames;
      return false;
    }
    counters_.lost_frames += static_cast<uint64_t>(gap - 1);
  }
  ++counters_.sensor_frames;
  last_rx_host_us_ = host_rx_us;
  last_device_status_ = frame.status;

  int64_t utime = clock_.Map(frame.device_time_us, host_rx_us);
  // A first frame that was delayed more than a sample period lets the
  // offset drop by more than one period later; never publish time backwards.
  if (have_sample_) utime = std::max(utime, latest_sample_utime_ + 1);
  const int64_t delay_us = host_rx_us - utime;
  counters_.delay_us.Add(delay_us);
  if (delay_us > static_cast<int64_t>(hw_.late_frame_s * 1e6)) ++counters_.late_frames;

  sample->utime = utime;
  sample->seq = frame.seq;
  sample->status = frame.status & kSensorStatusMask;
  bool leg_fault = frame.leg_fault_mask != 0;
  for (int i = 0; i < kNumLegs; ++i) {
    const uint16_t adc = frame.adc[static_cast<std::size_t>(i)];
    leg_fault = leg_fault || !calibration_.Plausible(i, adc);
    sample->leg_length_m(i) = calibration_.LengthM(i, adc);
  }
  if (leg_fault) {
    sample->status |= kStatusLegFault;
    ++counters_.leg_fault_samples;
  }
  sample->gyro_radps = imu_.GyroRadps(frame.gyro_raw);
  sample->accel_mps2 = imu_.AccelMps2(frame.accel_raw);
  if (ImuScale::Saturated(frame.gyro_raw) || ImuScale::Saturated(frame.accel_raw)) {
    sample->status |= kStatusImuFault;
  }
  if ((sample->status & kStatusImuFault) != 0) ++counters_.imu_fault_samples;
  if ((frame.status & kStatusWatchdog) != 0) ++counters_.device_watchdog_samples;
  counters_.device_rx_corrupt = frame.rx_corrupt;
  counters_.device_rx_lost = frame.rx_lost;
  counters_.device_rx_session_rejected = frame.rx_session_rejected;
  // Drive goes out only while the device follows this bridge: at start-up
  // until it adopts the session, after a device restart until it adopts it
  // again (CurrentReason).
  device_session_ = frame.command_session;
  if (device_session_ != link_session_) ++counters_.session_pending_samples;

  int64_t rtt_us = 0;
  // A seq of another session's frame says nothing about this bridge's.
  if (device_session_ == link_session_ &&
      rtt_.OnEcho(frame.last_command_seq, frame.command_age_us, host_rx_us, &rtt_us)) {
    counters_.rtt_us.Add(rtt_us);
  }

  have_sample_ = true;
  last_sample_seq_ = frame.seq;
  latest_sample_utime_ = utime;
  acceptor_.OnSamplePublished(utime);
  tick_frame_due_ = !sent_since_sample_;
  sent_since_sample_ = false;
  if (bringup_.enabled) {
    UpdateBringup(frame, *sample);
  } else if (actuator_guard_.OnReadings(utime, sample->leg_length_m, PlausibleMask(frame))) {
    // Tripped: the zero drive goes out with this sample, not with the next
    // command.
    tick_frame_due_ = true;
  }
  return true;
}

uint8_t HwBridge::PlausibleMask(const SensorFrame& frame) const {
  uint8_t plausible = 0;
  for (int i = 0; i < kNumLegs; ++i) {
    if (calibration_.Plausible(i, frame.adc[static_cast<std::size_t>(i)]) &&
        ((frame.leg_fault_mask >> i) & 1U) == 0) {
      plausible |= static_cast<uint8_t>(1U << i);
    }
  }
  return plausible;
}

void HwBridge::UpdateBringup(const SensorFrame& frame, const SensorSample& sample) {
  uint8_t plausible = 0;
  for (int i = 0; i < kNumLegs; ++i) {
    if (calibration_.Plausible(i, frame.adc[static_cast<std::size_t>(i)])) {
      plausible |= static_cast<uint8_t>(1U << i);
    }
  }
  const uint8_t tripped = guard_.Update(sample.utime, sample.leg_length_m, plausible);
  for (int i = 0; i < kNumLegs; ++i) counters_.guard_trips += (tripped >> i) & 1U;
  // A leg just tripped: its zero drive goes out with this sample, not with
  // the next command.
  if (tripped != 0) tick_frame_due_ = true;

  applied_.sample_utime = sample.utime;
  applied_.device_watchdog = (frame.status & kStatusWatchdog) != 0;
  applied_.guard_mask = static_cast<uint8_t>(guard_.tripped_mask() | guard_.limited_mask());
  // Since when the device has applied this drive: a frame that repeats the
  // drive in force (a keep-alive, two commands in a row after the program
  // stalled) changes nothing, so the time stays that of the frame that
  // changed it, not of the latest frame.
  const bool changed = !have_applied_ || frame.applied_drive != applied_drive_;
  applied_drive_ = frame.applied_drive;
  have_applied_ = true;
  if (!changed) return;
  applied_.duty = drive_map_.Duty(frame.applied_drive);
  if (frame.last_command_seq == 0) {
    applied_.since_utime = 0;  // nothing applied yet
  } else {
    applied_.since_utime = sample.utime - static_cast<int64_t>(frame.command_age_us);
    // The watchdog cut the frame's drive at its expiry, not at its arrival.
    if (applied_.device_watchdog) applied_.since_utime += sent_watchdog_us_;
  }
}

FrameOutcome HwBridge::OnFrame(const DecodedFrame& frame, int64_t host_rx_us,
                               SensorSample* sample) {
  if (frame.type != FrameType::kSensor) return FrameOutcome::kUnexpectedType;
  return OnSensorFrame(frame.sensor, host_rx_us, sample) ? FrameOutcome::kPublish
                                                         : FrameOutcome::kDropped;
}

CommandVerdict HwBridge::AcceptCommand(int64_t utime, bool finite) {
  if (!finite) {
    command_invalid_ = true;
    return CommandVerdict::kNonFinite;
  }
  const auto timeout_us = static_cast<int64_t>(hw_.command_timeout_s * 1e6);
  if (!have_sample_ || utime > latest_sample_utime_ + timeout_us) return CommandVerdict::kFuture;
  if (have_command_ && utime < command_utime_) return CommandVerdict::kOutOfOrder;
  have_command_ = true;
  command_invalid_ = false;
  command_utime_ = utime;
  ++counters_.commands_accepted;
  return CommandVerdict::kAccepted;
}

CommandVerdict HwBridge::OnSafeCommand(const ForceCommand& c, bool authentic) {
  if (bringup_.enabled) return CommandVerdict::kWrongMode;
  last_rejection_ = acceptor_.Check(c, authentic);
  if (last_rejection_ == CommandRejection::kNonFiniteForce) {
    // The current session's own command, in order and fresh, but broken:
    // zero drive at once rather than hold the previous one.
    return AcceptCommand(c.sample_utime, false);
  }
  if (last_rejection_ != CommandRejection::kNone) return CommandVerdict::kUntrusted;
  const CommandVerdict verdict = AcceptCommand(c.sample_utime, true);
  if (verdict != CommandVerdict::kAccepted) return verdict;
  command_drive_off_ = (c.flags & kCommandDriveOff) != 0;
  command_force_n_ = command_drive_off_ ? Vector6d::Zero() : c.force_n;
  // The last line: a force beyond the bound, whoever sent it, trips the
  // guard; the frame this command triggers goes out with zero drive.
  if (!command_drive_off_) actuator_guard_.OnForceCommand(c.force_n);
  return verdict;
}

GuardResetResult HwBridge::OnOperatorReset() {
  if (bringup_.enabled) return GuardResetResult::kNotTripped;
  return actuator_guard_.Reset();
}

CommandVerdict HwBridge::OnDutyCommand(int64_t utime, const Vector6d& duty) {
  if (!bringup_.enabled) return CommandVerdict::kWrongMode;
  const CommandVerdict verdict = AcceptCommand(utime, duty.allFinite());
  if (verdict == CommandVerdict::kAccepted) command_duty_ = duty;
  return verdict;
}

DriveReason HwBridge::CurrentReason(int64_t host_now_us) const {
  if (!bringup_.enabled && actuator_guard_.tripped()) return DriveReason::kGuard;
  // Before the device follows this bridge, a frame with drive would be
  // refused (it adopts a session only at rest) or, worse, be the first
  // word of a link whose other end is not known.
  if (device_session_ != link_session_) return DriveReason::kSessionPending;
  if (command_invalid_) return DriveReason::kInvalid;
  if (!have_command_) return DriveReason::kMissing;
  // Age in stack time: how far the device's samples have moved on since the
  // sample this command was computed from; and to now on the host's clock,
  // so that a bridge that was not running (descheduled, stopped) and reads
  // a backlog of the device's frames does not forward a command from before
  // the stall as young against them.
  const int64_t now_utime = std::max(latest_sample_utime_, host_now_us);
  const double age_s = static_cast<double>(now_utime - command_utime_) * 1e-6;
  if (age_s > hw_.command_timeout_s) return DriveReason::kStale;
  if (command_drive_off_) return DriveReason::kDriveOff;
  return DriveReason::kCommand;
}

std::size_t HwBridge::BuildCommandFrame(int64_t host_now_us, uint8_t* out) {
  CommandFrame frame;
  frame.seq = next_command_seq_++;
  frame.watchdog_us = static_cast<uint32_t>(std::lround(hw_.device_watchdog_s * 1e6));
  frame.flags = kCommandEnable;
  frame.session = link_session_;
  last_reason_ = CurrentReason(host_now_us);
  if (last_reason_ == DriveReason::kCommand && bringup_.enabled) {
    // The duty as commanded, after the guard on the latest readings.
    const Vector6d duty = guard_.Apply(command_duty_);
    if (guard_.limited_mask() != 0) ++counters_.guard_limited_frames;
    const DriveResult drive = drive_map_.DutyToDrive(duty);
    frame.drive = drive.drive;
    for (int i = 0; i < kNumLegs; ++i) {
      counters_.duty_clamped += (drive.duty_clamped_mask >> i) & 1U;
    }
  } else if (last_reason_ == DriveReason::kCommand) {
    counters_.applied_age_max_us =
        std::max(counters_.applied_age_max_us, latest_sample_utime_ - command_utime_);
    const DriveResult drive = drive_map_.ForceToDrive(command_force_n_);
    frame.drive = drive.drive;
    for (int i = 0; i < kNumLegs; ++i) {
      counters_.force_clamped += (drive.force_clamped_mask >> i) & 1U;
      counters_.duty_clamped += (drive.duty_clamped_mask >> i) & 1U;
      counters_.force_deadzoned += (drive.deadzone_mask >> i) & 1U;
    }
  } else {
    // Zero drive: the P-16P's lead screw holds its length unpowered. ENABLE
    // clear, so the device's samples say the actuators are off (status
    // ACTUATORS_OFF) while this frame is in force: the estimator then
    // predicts the legs held instead of moved by the last safe command,
    // which did not reach them.
    frame.flags = 0;
    frame.drive.fill(0);
    ++counters_.zero_drive_frames;
    if (last_reason_ == DriveReason::kDriveOff) ++counters_.drive_off_frames;
    if (last_reason_ == DriveReason::kGuard) ++counters_.guard_frames;
    if (last_reason_ == DriveReason::kSessionPending) ++counters_.session_pending_frames;
  }
  ++counters_.command_frames;
  sent_watchdog_us_ = frame.watchdog_us;
  rtt_.OnSent(frame.seq, host_now_us);
  sent_since_sample_ = true;
  tick_frame_due_ = false;
  return EncodeCommandFrame(frame, out);
}

bool HwBridge::LinkDown(int64_t host_now_us) const {
  if (!have_sample_) return true;
  return static_cast<double>(host_now_us - last_rx_host_us_) * 1e-6 > hw_.link_timeout_s;
}

LinkHealth HwBridge::Health(int64_t host_now_us, const std::string& link_description) const {
  const uint16_t device_faults = last_device_status_ & (kStatusLegFault | kStatusImuFault |
                                                        kStatusWatchdog | kStatusSupplyLow);
  if (counters_.sensor_frames == 0) {
    return {LinkState::kStarting, "no sensor frame from the device yet (" + link_description + ")"};
  }
  if (LinkDown(host_now_us)) {
    return {LinkState::kFault, "device link down: no sensor frame for > link_timeout_s"};
  }
  if (!bringup_.enabled && actuator_guard_.tripped()) {
    return {LinkState::kFault, "guard tripped: " + actuator_guard_.Describe() +
                                   "; zero drive (lead screws hold) until an operator RESET "
                                   "with the readings back inside"};
  }
  if (last_reason_ == DriveReason::kSessionPending) {
    return {LinkState::kDegraded,
            "zero drive: the device follows link session " + std::to_string(device_session_) +
                ", not this bridge's " + std::to_string(link_session_) +
                " (it adopts a new session only at rest, when no other bridge drives it)"};
  }
  if (last_reason_ != DriveReason::kCommand) {
    return {LinkState::kDegraded,
            std::string("zero drive: ") + ToString(last_reason_) +
                (bringup_.enabled ? " duty command (bring-up)" : " safe command")};
  }
  if (bringup_.enabled && guard_.tripped_mask() != 0) {
    std::string legs;
    for (int i = 0; i < kNumLegs; ++i) {
      if ((guard_.tripped_mask() >> i) & 1U) {
        legs += (legs.empty() ? "" : ", ") + std::to_string(i) + " (" + ToString(guard_.reason(i)) +
                ")";
      }
    }
    return {LinkState::kDegraded, "bring-up guard holds leg " + legs +
                                      " at zero duty until a zero duty command re-arms it"};
  }
  if (device_faults != 0) {
    return {LinkState::kDegraded, "device status " + std::to_string(last_device_status_)};
  }
  return {LinkState::kOk, ""};
}

}  // namespace stewart::hw
