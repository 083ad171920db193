#pragma once
// What the actuator identification needs of a device (docs/hardware.md,
// "Identify the actuators"): set a PWM duty per leg, read back time-stamped
// leg lengths, and learn when the device applied which duty. No LCM: the
// tool adapts hw_bridge's bring-up channels to it, and the in-process
// devices (plant_device.h, emulator_device.h) adapt plant_sim's Plant and
// the device emulator.
#include <cstdint>

#include "stewart/model/types.h"

namespace stewart::identify {

/// One sample of the legs as the device reports it.
struct ActuatorSample {
  int64_t utime = 0;                         ///< sample time (us, the stack's time base)
  Vector6d leg_length_m = Vector6d::Zero();  ///< potentiometer readings (m)
  /// False when the device flags the sample (a leg or pot fault).
  bool valid = true;
  /// The duty the device applied at the sample instant (positive extends),
  /// and the time from which it applied it (us, same time base): the
  /// device's echo, so the fit needs no assumption about the command's
  /// latency. applied_since_utime <= utime.
  Vector6d applied_duty = Vector6d::Zero();
  int64_t applied_since_utime = 0;
  /// Legs a guard on the device side (hw_bridge's bring-up guard) holds at
  /// zero duty (bit i).
  uint8_t device_guard_mask = 0;
};

class ActuatorDevice {
 public:
  virtual ~ActuatorDevice() = default;
  /// The next sample, waiting for it. Throws IdentificationError when the
  /// device delivers none in time (the link is down).
  virtual ActuatorSample NextSample() = 0;
  /// The duty per leg from now on (each in [-1, 1], positive extends),
  /// answering the sample of sample_utime. The device holds it until the
  /// next call, or zeroes it when calls stop (its own watchdog).
  virtual void SetDuty(int64_t sample_utime, const Vector6d& duty) = 0;
};

}  // namespace stewart::identify
