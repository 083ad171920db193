#pragma once
// The device side of the wire protocol (docs/wire-protocol.md): holds the
// latest command under the device watchdog, runs a backend in device time,
// and produces a sensor frame per sample. No I/O: EmulatorNode drives it.
//
// Time is the device clock (us). The backend's physics is advanced event by
// event: a command frame takes effect at the instant it arrives (as the
// myRIO updates its PWM outputs), the watchdog zeroes the drive at the exact
// instant it expires, and a sample reads the state at its own instant.
#include <cstdint>

#include "stewart/hw_bridge/wire_format.h"
#include "stewart/hw_emulator/command_session_check.h"
#include "stewart/hw_emulator/device_backend.h"

namespace stewart::hw {

class DeviceEmulator {
 public:
  explicit DeviceEmulator(DeviceBackend* backend) : backend_(backend) {}

  /// A decoded command frame that arrived at device time now_us. When the
  /// session check accepts it (CommandSessionCheck: its session's next
  /// frame, or a new session's start) the physics runs up to now_us under
  /// the drive in force before it, then this frame's drive applies; any
  /// other frame changes nothing (and is counted when of another session).
  CommandAcceptance OnCommandFrame(const CommandFrame& frame, uint64_t now_us);
  /// A command frame the device rejected (bad CRC, length, field ...).
  void OnRxError() { ++rx_corrupt_; }

  /// The sample at device time now_us: runs the physics up to now_us, samples
  /// the backend and returns the frame to send. The first call (or command)
  /// starts the device clock: the backend's state is the state at that time.
  SensorFrame Tick(uint64_t now_us);

  /// Drive applied over the last stretch of physics before the latest event.
  const DriveArray& applied_drive() const { return applied_drive_; }
  const CommandSessionCheck& sessions() const { return sessions_; }

 private:
  /// The drive in force over an interval starting at t_us, and the status
  /// bits that explain a zero drive (ACTUATORS_OFF, WATCHDOG).
  DriveArray DriveFrom(uint64_t t_us, uint16_t* status) const;
  /// Runs the backend from physics_us_ to t_us, splitting at the watchdog's
  /// expiry. Never goes back in time.
  void AdvanceTo(uint64_t t_us);

  DeviceBackend* backend_;
  bool started_ = false;
  uint64_t physics_us_ = 0;  ///< device time the backend's state belongs to
  bool have_command_ = false;
  CommandFrame command_;
  uint64_t command_rx_us_ = 0;
  DriveArray applied_drive_{};
  CommandSessionCheck sessions_;
  uint32_t next_seq_ = 0;
  uint32_t rx_corrupt_ = 0;
};

}  // namespace stewart::hw
