#pragma once
#include <string>

#include "stewart/model/types.h"

namespace stewart {

/// `hw_bridge`: transport, calibration and drive map of the real device
/// (docs/wire-protocol.md, docs/hardware.md).
struct HwBridgeConfig {
  std::string transport = "udp";  ///< udp | serial
  std::string device_host = "127.0.0.1";
  int device_port = 0;
  std::string local_host = "127.0.0.1";
  int local_port = 0;
  std::string serial_device;
  int serial_baud = 0;
  double command_timeout_s = 0.05;  ///< stack-time age of a safe command before zero drive
  double device_watchdog_s = 0.05;  ///< sent to the device in every command frame
  double link_timeout_s = 0.1;      ///< no sensor frame this long -> FAULT
  double late_frame_s = 0.005;      ///< arrival later than this after the sample -> late
  double clock_drift_ppm = 200.0;   ///< bound on device clock drift (time mapping)

  // Leg potentiometers: two-point calibration per leg (ADC counts).
  int adc_max_count = 4095;
  int adc_fault_margin_counts = 40;
  Vector6d adc_retracted = Vector6d::Zero();  ///< counts at actuators.min_length_m
  Vector6d adc_extended = Vector6d::Zero();   ///< counts at min_length_m + stroke_m
  Vector6d length_offset_m = Vector6d::Zero();

  // IMU raw scales.
  double gyro_radps_per_lsb = 0.0;
  double accel_mps2_per_lsb = 0.0;

  // Force -> duty map and clamps.
  double force_at_full_duty_n = 100.0;
  double duty_deadband = 0.0;              ///< [0, 1)
  double force_deadzone_n = 0.0;           ///< >= 0
  double max_duty = 1.0;                   ///< (0, 1]
  Vector6d drive_sign = Vector6d::Ones();  ///< +1 or -1 per leg
};


}  // namespace stewart
