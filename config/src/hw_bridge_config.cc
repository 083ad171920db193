#include <climits>
#include <cmath>

#include "stewart/config/sections.h"
#include "stewart/model/dc_motor.h"

namespace stewart {

HwBridgeConfig ParseHwBridgeConfig(const ConfigNode& hw_bridge, const ActuatorConfig& actuators) {
  HwBridgeConfig h;
  h.transport = hw_bridge.Choice("transport", {"udp", "serial"});
  h.device_host = hw_bridge.String("device_host");
  h.local_host = hw_bridge.String("local_host");
  const std::string udp_port = "must be a UDP port 0..65535";
  h.device_port = hw_bridge.IntInRange("device_port", 0, 65535, udp_port);
  h.local_port = hw_bridge.IntInRange("local_port", 0, 65535, udp_port);
  h.serial_device = hw_bridge.String("serial_device");
  h.serial_baud = hw_bridge.IntInRange("serial_baud", 1, INT_MAX, "must be positive");
  h.command_timeout_s = hw_bridge.PositiveDouble("command_timeout_s");
  h.device_watchdog_s = hw_bridge.PositiveDouble("device_watchdog_s");
  // The frame carries the watchdog in whole microseconds, 1 ms .. 1 s.
  if (h.device_watchdog_s < 1e-3 || h.device_watchdog_s > 1.0) {
    hw_bridge.Fail("device_watchdog_s", "must be within [0.001, 1] s");
  }
  h.link_timeout_s = hw_bridge.PositiveDouble("link_timeout_s");
  h.late_frame_s = hw_bridge.PositiveDouble("late_frame_s");
  h.clock_drift_ppm = hw_bridge.NonNegativeDouble("clock_drift_ppm");

  h.adc_max_count = hw_bridge.IntInRange("adc_max_count", 1, 65535,
                                         "must be within [1, 65535] (uint16 on the wire)");
  h.adc_fault_margin_counts =
      hw_bridge.IntInRange("adc_fault_margin_counts", 0, INT_MAX, "must be >= 0");
  h.adc_retracted = hw_bridge.Vec6("adc_retracted");
  h.adc_extended = hw_bridge.Vec6("adc_extended");
  for (int i = 0; i < 6; ++i) {
    const double lo = h.adc_retracted(i);
    const double hi = h.adc_extended(i);
    if (lo < 0 || lo > h.adc_max_count) {
      hw_bridge.Fail("adc_retracted", "leg " + std::to_string(i) + " outside [0, adc_max_count]");
    }
    if (hi < 0 || hi > h.adc_max_count) {
      hw_bridge.Fail("adc_extended", "leg " + std::to_string(i) + " outside [0, adc_max_count]");
    }
    // A reversed pot is allowed (hi < lo), a degenerate span is not.
    if (std::abs(hi - lo) < 100.0) {
      hw_bridge.Fail("adc_extended",
                     "leg " + std::to_string(i) + ": span to adc_retracted below 100 counts");
    }
  }
  h.length_offset_m = hw_bridge.Vec6("length_offset_m");

  h.gyro_radps_per_lsb = hw_bridge.PositiveDouble("gyro_radps_per_lsb");
  h.accel_mps2_per_lsb = hw_bridge.PositiveDouble("accel_mps2_per_lsb");

  if (actuators.kind == ActuatorKind::kDcMotor) {
    // One source for the motor's input map: actuators.motor.
    for (const char* key : {"force_at_full_duty_n", "duty_deadband"}) {
      if (hw_bridge.Has(key)) {
        hw_bridge.Fail(key, "is set by actuators.motor when actuators.model is dc_motor");
      }
    }
    h.force_at_full_duty_n = DcMotorForceAtFullDuty(actuators.motor);
    h.duty_deadband = actuators.motor.dead_band_duty;
  } else {
    h.force_at_full_duty_n = hw_bridge.PositiveDouble("force_at_full_duty_n");
    h.duty_deadband = hw_bridge.NonNegativeDouble("duty_deadband");
    if (h.duty_deadband >= 1.0) hw_bridge.Fail("duty_deadband", "must be < 1");
  }
  h.force_deadzone_n = hw_bridge.NonNegativeDouble("force_deadzone_n");
  h.max_duty = hw_bridge.PositiveDouble("max_duty");
  if (h.max_duty > 1.0) hw_bridge.Fail("max_duty", "must be <= 1");
  h.drive_sign = hw_bridge.Vec6("drive_sign");
  for (int i = 0; i < 6; ++i) {
    if (h.drive_sign(i) != 1.0 && h.drive_sign(i) != -1.0) {
      hw_bridge.Fail("drive_sign", "leg " + std::to_string(i) + ": must be 1 or -1");
    }
  }
  return h;
}

}  // namespace stewart
