#include "stewart/hw_bridge/calibration.h"

#include <cmath>

namespace stewart::hw {
namespace {

bool ToRaw(const Vector3d& value, double per_lsb, std::array<int16_t, 3>* raw) {
  bool ok = true;
  for (int i = 0; i < 3; ++i) {
    double counts = std::round(value(i) / per_lsb);
    if (!(counts < 32767.0)) {  // also catches NaN
      counts = std::isnan(counts) ? 0.0 : 32767.0;
      ok = false;
    }
    if (counts < -32767.0) {
      counts = -32767.0;
      ok = false;
    }
    (*raw)[static_cast<std::size_t>(i)] = static_cast<int16_t>(counts);
  }
  return ok;
}

}  // namespace

LegCalibration::LegCalibration(const HwBridgeConfig& hw, double min_length_m, double stroke_m)
    : min_length_m_(min_length_m),
      stroke_m_(stroke_m),
      adc_retracted_(hw.adc_retracted),
      adc_extended_(hw.adc_extended),
      length_offset_m_(hw.length_offset_m),
      margin_counts_(hw.adc_fault_margin_counts),
      adc_max_(hw.adc_max_count) {}

double LegCalibration::LengthM(int leg, uint16_t adc) const {
  const double fraction = (adc - adc_retracted_(leg)) / (adc_extended_(leg) - adc_retracted_(leg));
  return min_length_m_ + length_offset_m_(leg) + fraction * stroke_m_;
}

bool LegCalibration::Plausible(int leg, uint16_t adc) const {
  const double lo = std::min(adc_retracted_(leg), adc_extended_(leg)) - margin_counts_;
  const double hi = std::max(adc_retracted_(leg), adc_extended_(leg)) + margin_counts_;
  return adc >= lo && adc <= hi && adc <= adc_max_;
}

double LegCalibration::AdcCounts(int leg, double length_m) const {
  const double fraction = (length_m - min_length_m_ - length_offset_m_(leg)) / stroke_m_;
  return adc_retracted_(leg) + fraction * (adc_extended_(leg) - adc_retracted_(leg));
}

Vector3d ImuScale::GyroRadps(const std::array<int16_t, 3>& raw) const {
  return Vector3d(raw[0], raw[1], raw[2]) * gyro_;
}

Vector3d ImuScale::AccelMps2(const std::array<int16_t, 3>& raw) const {
  return Vector3d(raw[0], raw[1], raw[2]) * accel_;
}

bool ImuScale::GyroRaw(const Vector3d& radps, std::array<int16_t, 3>* raw) const {
  return ToRaw(radps, gyro_, raw);
}

bool ImuScale::AccelRaw(const Vector3d& mps2, std::array<int16_t, 3>* raw) const {
  return ToRaw(mps2, accel_, raw);
}

bool ImuScale::Saturated(const std::array<int16_t, 3>& raw) {
  for (int16_t v : raw) {
    if (v >= 32767 || v <= -32767) return true;
  }
  return false;
}

}  // namespace stewart::hw
