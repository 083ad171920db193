#include "stewart/hw_bridge/drive_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stewart/hw_bridge/wire_format.h"

namespace stewart::hw {

namespace {

ForceToDutyMap UnclampedMap(const HwBridgeConfig& hw) {
  ForceToDutyMap map;
  map.force_limit_n = std::numeric_limits<double>::infinity();
  map.force_at_full_duty_n = hw.force_at_full_duty_n;
  map.dead_band_duty = hw.duty_deadband;
  map.max_duty = std::numeric_limits<double>::infinity();
  return map;
}

}  // namespace

DriveMap::DriveMap(const HwBridgeConfig& hw, double force_limit_n)
    : force_limit_n_(force_limit_n),
      map_(UnclampedMap(hw)),
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
      duty = DutyForForce(map_, f_c);
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
  const Vector6d duty = Duty(drive);
  Vector6d force;
  for (int i = 0; i < kNumLegs; ++i) force(i) = ForceForDuty(map_, duty(i));
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
    locked[i] = EffectiveDuty(map_, drive[i] / static_cast<double>(kDriveFullScale)) == 0.0;
  }
  return locked;
}

}  // namespace stewart::hw
