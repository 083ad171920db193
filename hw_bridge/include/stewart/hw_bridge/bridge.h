#pragma once
// The host side of the device link, without LCM: sensor frames -> SI
// samples in the stack's time base, safe force commands -> command frames,
// with the command watchdog and the link statistics, and what the node
// reports about the link. BridgeNode (hw_bridge/node) wires it to LCM and a
// Transport.
//
// In normal operation only the announced safety session's commands move the
// legs (SafeCommandAcceptor, guard/), and the bridge's own last-line guard
// on its own pot readings (ActuatorGuard) turns the drive off, latched until
// an operator RESET (docs/operations.md, "Trust model").
//
// Each bridge has its own link session (link_session.h): its command frames
// carry zero drive until the device echoes that session, i.e. follows this
// bridge and no other (docs/wire-protocol.md, "Sessions").
#include <cstddef>
#include <cstdint>
#include <string>

#include "stewart/common/enum_table.h"
#include "stewart/common/signals.h"
#include "stewart/guard/actuator_guard.h"
#include "stewart/guard/guard_config.h"
#include "stewart/guard/safe_command_acceptor.h"
#include "stewart/hw_bridge/bringup.h"
#include "stewart/hw_bridge/calibration.h"
#include "stewart/hw_bridge/drive_map.h"
#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/hw_bridge/link_stats.h"
#include "stewart/hw_bridge/wire_format.h"
#include "stewart/model/types.h"

namespace stewart::hw {

/// One sample in SI units; the node copies it into sensor_t.
struct SensorSample {
  int64_t utime = 0;  ///< host time base (us), DeviceClockMap
  int64_t seq = 0;    ///< device frame seq
  Vector6d leg_length_m = Vector6d::Zero();
  Vector3d gyro_radps = Vector3d::Zero();
  Vector3d accel_mps2 = Vector3d::Zero();
  int32_t status = 0;  ///< sensor_t.STATUS_* bits
};

/// Why the last command frame carried what it carried. In bring-up mode
/// (bringup.h) "command" is the latest duty command, else the latest safe
/// force command.
enum class DriveReason {
  kCommand,         ///< the latest command, mapped
  kMissing,         ///< no valid command received yet: zero drive
  kStale,           ///< the held command is older than command_timeout_s: zero drive
  kInvalid,         ///< the latest command was non-finite: zero drive
  kDriveOff,        ///< the latest safe command says FLAG_DRIVE_OFF: zero drive
  kGuard,           ///< the last-line guard has tripped (latched): zero drive
  kSessionPending,  ///< the device does not (yet) follow this bridge's link session: zero drive
};
inline constexpr EnumTable<DriveReason, 7> kDriveReasonNames{{{
    {DriveReason::kCommand, "command"},
    {DriveReason::kMissing, "missing"},
    {DriveReason::kStale, "stale"},
    {DriveReason::kInvalid, "invalid"},
    {DriveReason::kDriveOff, "drive_off"},
    {DriveReason::kGuard, "guard"},
    {DriveReason::kSessionPending, "session_pending"},
}}};
inline const char* ToString(DriveReason reason) { return kDriveReasonNames.Name(reason).data(); }

enum class CommandVerdict {
  kAccepted,
  kNonFinite,   ///< NaN/Inf force: rejected, zero drive until a valid one
  kOutOfOrder,  ///< older than the held command: ignored
  kFuture,      ///< newer than the newest sample by more than the timeout:
                ///< another time base (a second stack?), ignored
  kWrongMode,   ///< a force command in bring-up mode, a duty command outside it: ignored
  kUntrusted,   ///< the acceptor refused it (HwBridge::last_rejection() says why): ignored
};
inline constexpr EnumTable<CommandVerdict, 6> kCommandVerdictNames{{{
    {CommandVerdict::kAccepted, "accepted"},
    {CommandVerdict::kNonFinite, "non_finite_command"},
    {CommandVerdict::kOutOfOrder, "out_of_order_command"},
    {CommandVerdict::kFuture, "future_command"},
    {CommandVerdict::kWrongMode, "wrong_mode_command"},
    {CommandVerdict::kUntrusted, "untrusted_command"},
}}};
inline const char* ToString(CommandVerdict verdict) {
  return kCommandVerdictNames.Name(verdict).data();
}

/// Whether a command frame goes out as soon as the command is in: a valid
/// command at once, and a non-finite one at once as zero drive. An ignored
/// command changes nothing the device must hear about.
bool SendsAtOnce(CommandVerdict verdict);

/// What a decoded frame from the device means for the node.
enum class FrameOutcome {
  kPublish,         ///< a new sensor sample: publish it
  kDropped,         ///< a sensor frame not to publish (duplicate, reordered)
  kUnexpectedType,  ///< not a sensor frame: the device never sends one
};

/// The link's state as the heartbeat reports it.
enum class LinkState { kStarting, kOk, kDegraded, kFault };
struct LinkHealth {
  LinkState state = LinkState::kStarting;
  std::string error;  ///< "" when kOk
};

struct BridgeCounters {
  uint64_t sensor_frames = 0;
  uint64_t lost_frames = 0;       ///< sensor seq gaps
  uint64_t late_frames = 0;       ///< arrived > late_frame_s after the sample time
  uint64_t reordered_frames = 0;  ///< seq not newer than the last: dropped
  uint64_t leg_fault_samples = 0;
  uint64_t imu_fault_samples = 0;
  uint64_t device_watchdog_samples = 0;
  uint64_t command_frames = 0;
  uint64_t commands_accepted = 0;
  uint64_t zero_drive_frames = 0;  ///< frames sent with zero drive for a DriveReason != kCommand
  uint64_t force_clamped = 0;      ///< legs clamped to the force limit (frames x legs)
  uint64_t duty_clamped = 0;
  uint64_t force_deadzoned =
      0;                     ///< legs whose non-zero force fell in the dead zone (frames x legs)
  uint64_t guard_trips = 0;  ///< bring-up: legs the guard tripped (events)
  uint64_t drive_off_frames = 0;  ///< frames sent with zero drive for the supervisor's drive off
  uint64_t guard_frames = 0;      ///< frames sent with zero drive for the tripped last-line guard
  uint64_t session_pending_frames = 0;   ///< frames sent with zero drive before the device's echo
  uint64_t session_pending_samples = 0;  ///< samples whose echoed session was not this bridge's
  int64_t applied_age_max_us = 0;        ///< oldest command whose force went out (sample age, us)
  uint64_t guard_limited_frames = 0;  ///< bring-up: frames in which the guard zeroed a leg's duty
  uint64_t device_rx_corrupt = 0;     ///< the device's own counters (latest)
  uint64_t device_rx_lost = 0;
  uint64_t device_rx_session_rejected = 0;  ///< frames of a session the device did not adopt
  WindowStats rtt_us;                       ///< command round trip, per health window
  WindowStats delay_us;                     ///< host arrival - sample utime, per health window
};

class HwBridge {
 public:
  /// `bringup`: hw_bridge --bringup (bringup.h); off by default. `guard`:
  /// the config's `guard:` section (sessions, the last-line guard's limits).
  /// The link session is drawn at random here (NewLinkSession).
  HwBridge(const HwBridgeConfig& hw, double min_length_m, double stroke_m, double force_limit_n,
           const BringupOptions& bringup = {}, const GuardConfig& guard = {});

  /// This bridge's link session, in every command frame.
  uint32_t link_session() const { return link_session_; }
  /// The session the device follows, as its latest sensor frame echoed it
  /// (0: none, or no frame yet).
  uint32_t device_session() const { return device_session_; }

  /// A decoded sensor frame that arrived at host_rx_us. Returns false (and
  /// counts) when it must not be published: duplicate or reordered.
  bool OnSensorFrame(const SensorFrame& frame, int64_t host_rx_us, SensorSample* sample);
  /// Any decoded frame from the device; *sample is set for kPublish.
  FrameOutcome OnFrame(const DecodedFrame& frame, int64_t host_rx_us, SensorSample* sample);

  /// A session announcement (supervisor_state_t); `authentic`: its MAC
  /// verified; `wall_us`: the host's monotonic clock.
  AnnouncementVerdict OnAnnouncement(const SessionAnnouncement& a, bool authentic,
                                     int64_t wall_us) {
    return acceptor_.OnAnnouncement(a, authentic, wall_us);
  }
  /// A safe command (force_command_t); `authentic`: its MAC verified (true
  /// without a key). kWrongMode in bring-up; kUntrusted when the acceptor
  /// refuses it (last_rejection()). An accepted command beyond the guard's
  /// force bound trips the guard: accepted, and zero drive.
  CommandVerdict OnSafeCommand(const ForceCommand& command, bool authentic);
  CommandRejection last_rejection() const { return last_rejection_; }
  /// The operator's RESET (its MAC and freshness checked by the caller):
  /// clears the tripped guard iff the readings are back inside.
  GuardResetResult OnOperatorReset();
  /// Bring-up only (kWrongMode otherwise): a duty per leg (duty_command_t:
  /// utime = the sample it answers, duty positive extends), with the same
  /// checks of time and finiteness as a force command.
  CommandVerdict OnDutyCommand(int64_t utime, const Vector6d& duty);

  /// True when a sensor frame arrived and no command frame went out since
  /// the previous one: the keep-alive frame of this tick is due.
  bool TickFrameDue() const { return tick_frame_due_; }

  /// Encodes the next command frame into out (kMaxFrameSize bytes) and
  /// remembers its send time for the round trip.
  std::size_t BuildCommandFrame(int64_t host_now_us, uint8_t* out);

  DriveReason last_reason() const { return last_reason_; }
  /// No sensor frame for link_timeout_s (or none yet).
  bool LinkDown(int64_t host_now_us) const;
  /// The heartbeat's state and error, worst first: no frame yet, link down,
  /// zero drive, device fault bits. `link_description` names the transport.
  LinkHealth Health(int64_t host_now_us, const std::string& link_description) const;
  int64_t latest_sample_utime() const { return latest_sample_utime_; }
  bool bringup() const { return bringup_.enabled; }
  /// Bring-up: what the device applied, as of the latest sensor frame.
  const AppliedDuty& applied() const { return applied_; }
  /// Bring-up: the guard on the bridge's readings.
  const LegGuard& guard() const { return guard_; }
  /// Normal operation: the last-line guard on the bridge's readings.
  const ActuatorGuard& actuator_guard() const { return actuator_guard_; }
  const SafeCommandAcceptor& acceptor() const { return acceptor_; }
  uint16_t last_device_status() const { return last_device_status_; }
  const BridgeCounters& counters() const { return counters_; }
  void ResetWindows() {
    counters_.rtt_us.Reset();
    counters_.delay_us.Reset();
  }

 private:
  /// `host_now_us`: now in the host time base of the samples' utime.
  DriveReason CurrentReason(int64_t host_now_us) const;
  /// Bit i: leg i's reading is in its calibrated span and not flagged.
  uint8_t PlausibleMask(const SensorFrame& frame) const;
  CommandVerdict AcceptCommand(int64_t utime, bool finite);
  void UpdateBringup(const SensorFrame& frame, const SensorSample& sample);

  HwBridgeConfig hw_;
  LegCalibration calibration_;
  ImuScale imu_;
  DriveMap drive_map_;
  DeviceClockMap clock_;
  RoundTripTracker rtt_;
  BridgeCounters counters_;

  bool have_sample_ = false;
  uint32_t last_sample_seq_ = 0;
  int64_t latest_sample_utime_ = 0;
  int64_t last_rx_host_us_ = 0;
  uint16_t last_device_status_ = 0;
  bool tick_frame_due_ = false;
  bool sent_since_sample_ = false;

  SafeCommandAcceptor acceptor_;
  ActuatorGuard actuator_guard_;
  CommandRejection last_rejection_ = CommandRejection::kNone;
  bool command_drive_off_ = false;

  bool have_command_ = false;
  bool command_invalid_ = false;
  int64_t command_utime_ = 0;
  Vector6d command_force_n_ = Vector6d::Zero();
  Vector6d command_duty_ = Vector6d::Zero();

  BringupOptions bringup_;
  LegGuard guard_;
  AppliedDuty applied_;
  DriveArray applied_drive_{};  // the device's applied drive, latest frame
  bool have_applied_ = false;
  uint32_t sent_watchdog_us_ = 0;
  uint32_t link_session_;
  uint32_t device_session_ = 0;
  uint32_t next_command_seq_ = 1;
  DriveReason last_reason_ = DriveReason::kMissing;
};

}  // namespace stewart::hw
