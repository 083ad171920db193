#include "stewart/hw_bridge/drive_map.h"

#include <algorithm>
#include <cmath>

#include "stewart/hw_bridge/wire_format.h"

namespace stewart::hw {

DriveMap::DriveMap(const HwBridgeConfig& hw, double force_limit_n)
    : force_limit_n_(force_limit_n),
      force_at_full_duty_n_(hw.force_at_full_duty_n),
      duty_deadband_(hw.duty_deadband),
      force_deadzone_n_(hw.force_deadzone_n),
      max_duty_(hw.max_duty),
      drive_sign_(hw.drive_sign) {}

DriveResult DriveMap::ForceToDrive(const Vector6d& force_n) const {
  DriveResult result;
  for (int i = 0; i < kNumLegs; ++i) {
    const double f = force_n(i);
    if (!std::isfinite(f)) continue;
    const double f_c = std::clamp(f, -force_limit_n_, force_limit_n_);
    if (f_c != f) result.force_clamped_mask |= static_cast<uint8_t>(1U << i);
    double duty = 0.0;
    if (std::abs(f_c) >= force_deadzone_n_ && f_c != 0.0) {
      duty = std::copysign(
          duty_deadband_ + (1.0 - duty_deadband_) * std::abs(f_c) / force_at_full_duty_n_, f_c);
    } else if (f_c != 0.0) {
      result.deadzone_mask |= static_cast<uint8_t>(1U << i);
    }
    if (std::abs(duty) > max_duty_) {
      duty = std::copysign(max_duty_, duty);
      result.duty_clamped_mask |= static_cast<uint8_t>(1U << i);
    }
    result.drive[static_cast<std::size_t>(i)] =
        static_cast<int16_t>(std::lround(drive_sign_(i) * duty * kDriveFullScale));
  }
  return result;
}

DriveResult DriveMap::DutyToDrive(const Vector6d& duty) const {
  DriveResult result;
  for (int i = 0; i < kNumLegs; ++i) {
    double d = duty(i);
    if (!std::isfinite(d)) continue;
    if (std::abs(d) > max_duty_) {
      d = std::copysign(max_duty_, d);
      result.duty_clamped_mask |= static_cast<uint8_t>(1U << i);
    }
    result.drive[static_cast<std::size_t>(i)] =
        static_cast<int16_t>(std::lround(drive_sign_(i) * d * kDriveFullScale));
  }
  return result;
}

Vector6d DriveMap::DriveToForce(const DriveArray& drive) const {
  Vector6d force = Vector6d::Zero();
  for (int i = 0; i < kNumLegs; ++i) {
    const double duty = drive_sign_(i) * drive[static_cast<std::size_t>(i)] / kDriveFullScale;
    const double excess = std::abs(duty) - duty_deadband_;
    if (excess <= 0.0) continue;
    force(i) = std::copysign(excess / (1.0 - duty_deadband_) * force_at_full_duty_n_, duty);
  }
  return force;
}

Vector6d DriveMap::Duty(const DriveArray& drive) const {
  Vector6d duty;
  for (int i = 0; i < kNumLegs; ++i) {
    duty(i) = drive_sign_(i) * drive[static_cast<std::size_t>(i)] / kDriveFullScale;
  }
  return duty;
}

std::array<bool, 6> DriveMap::Locked(const DriveArray& drive) const {
  std::array<bool, 6> locked{};
  for (std::size_t i = 0; i < 6; ++i) {
    locked[i] = std::abs(drive[i] / static_cast<double>(kDriveFullScale)) <= duty_deadband_;
  }
  return locked;
}

}  // namespace stewart::hw
