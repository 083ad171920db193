#pragma once
// hw_bridge's bring-up mode (hw_bridge --bringup; docs/hardware.md,
// "Identify the actuators"): before the safety filter is armed, a bring-up
// program (stewart_identify --mode actuators) drives each leg's PWM duty
// directly. The bridge then takes duty_command_t on <prefix>BRINGUP_DUTY
// instead of force_command_t on CMD_SAFE (which it rejects and counts), puts
// every duty through its own leg guard (leg_guard.h) on its own readings,
// zeroes the drive when commands stop (command_timeout_s of stack time, as
// in normal operation), and echoes on <prefix>BRINGUP_DUTY_APPLIED, per
// sensor sample, the duty the device reports it applied and since when.
// Never on in normal operation: tools/launch.sh does not pass the flag.
#include <cstdint>
#include <string>

#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/hw_bridge/leg_guard.h"
#include "stewart/model/actuator_params.h"
#include "stewart/model/types.h"

namespace stewart::hw {

struct BringupOptions {
  bool enabled = false;
  LegGuardLimits guard;
};

/// The guard's defaults: the stroke ends given, margin_m, and a speed cap
/// of twice the motor's full-duty no-load speed, F_full / b_emf (0.05 m/s
/// when the config has no motor values).
LegGuardLimits DefaultBringupGuard(double min_length_m, double max_length_m, double margin_m,
                                   const DcMotorParams& motor);

/// The guard of the pot calibration's stroke-end run (hw_bridge --bringup
/// --bringup-end-search; docs/hardware.md, "Calibrate the pots at the stroke
/// ends"): end zones half a millimetre wide, search_m beyond the nominal
/// stroke ends, so that legs whose pots read up to search_m off reach their
/// end stops.
LegGuardLimits StrokeEndSearchGuard(double min_length_m, double max_length_m, double search_m,
                                    double speed_cap_mps);

/// The pots' fault margin (counts) that lets readings search_m beyond a
/// stroke end through: the config's, plus search_m in counts of the leg with
/// the most counts per metre. Open (~0) and shorted (~adc_max) wipers stay
/// faults as long as the result is below the calibrated ends' distance to
/// them.
int FaultMarginForSearch(const HwBridgeConfig& hw, double stroke_m, double search_m);

/// What the device applied, from its sensor frame (the bring-up echo).
struct AppliedDuty {
  int64_t sample_utime = 0;  ///< the sensor sample that reported it
  /// Stack time from which the device has applied `duty`: when the frame
  /// that changed the drive arrived (the sample time minus the age the
  /// device reports for it), or the instant the watchdog cut it; frames that
  /// repeat the drive in force do not move it.
  int64_t since_utime = 0;
  Vector6d duty = Vector6d::Zero();  ///< per leg, positive extends
  uint8_t guard_mask = 0;            ///< legs the bridge's guard holds at zero duty
  bool device_watchdog = false;      ///< the device's watchdog zeroed the drive
};

/// Channel names: prefix + BRINGUP_DUTY (+ _APPLIED) + suffix.
inline std::string BringupDutyChannel(const std::string& prefix, const std::string& suffix) {
  return prefix + "BRINGUP_DUTY" + suffix;
}
inline std::string BringupAppliedChannel(const std::string& prefix, const std::string& suffix) {
  return prefix + "BRINGUP_DUTY_APPLIED" + suffix;
}

}  // namespace stewart::hw
