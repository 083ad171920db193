#pragma once
// Raw device readings <-> SI units (docs/hardware.md gives the calibration
// procedure that fills in the numbers).
#include <array>
#include <cstdint>

#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/model/types.h"

namespace stewart::hw {

/// Two-point linear pot calibration per leg:
///   leg_length_m = min_length_m + length_offset_m_i
///                  + (adc - adc_retracted_i) / (adc_extended_i - adc_retracted_i) * stroke_m
class LegCalibration {
 public:
  LegCalibration(const HwBridgeConfig& hw, double min_length_m, double stroke_m);

  double LengthM(int leg, uint16_t adc) const;
  /// False when the reading is outside the calibrated span by more than the
  /// fault margin (broken wire, shorted wiper, unplugged connector).
  bool Plausible(int leg, uint16_t adc) const;
  /// Inverse, unrounded (counts): for the emulator and calibration checks.
  double AdcCounts(int leg, double length_m) const;

 private:
  double min_length_m_;
  double stroke_m_;
  Vector6d adc_retracted_;
  Vector6d adc_extended_;
  Vector6d length_offset_m_;
  double margin_counts_;
  double adc_max_;
};

/// IMU raw int16 <-> SI, {P} axes.
class ImuScale {
 public:
  explicit ImuScale(const HwBridgeConfig& hw)
      : gyro_(hw.gyro_radps_per_lsb), accel_(hw.accel_mps2_per_lsb) {}

  Vector3d GyroRadps(const std::array<int16_t, 3>& raw) const;
  Vector3d AccelMps2(const std::array<int16_t, 3>& raw) const;
  /// Inverse with saturation at +-32767; returns false if any axis saturated.
  bool GyroRaw(const Vector3d& radps, std::array<int16_t, 3>* raw) const;
  bool AccelRaw(const Vector3d& mps2, std::array<int16_t, 3>* raw) const;
  /// A full-scale reading: the true value may be beyond the range.
  static bool Saturated(const std::array<int16_t, 3>& raw);

 private:
  double gyro_;
  double accel_;
};

}  // namespace stewart::hw
