#include "stewart/hw_bridge/leg_guard.h"

#include <cmath>

namespace stewart::hw {

void LegGuard::Trip(int leg, GuardReason reason) {
  const auto i = static_cast<std::size_t>(leg);
  if ((tripped_mask_ >> leg) & 1U) return;
  tripped_mask_ |= static_cast<uint8_t>(1U << leg);
  reason_[i] = reason;
}

uint8_t LegGuard::Update(int64_t utime, const Vector6d& leg_length_m, uint8_t plausible_mask) {
  const uint8_t before = tripped_mask_;
  plausible_mask_ = plausible_mask;
  for (int i = 0; i < kNumLegs; ++i) {
    const double l = leg_length_m(i);
    if (!std::isfinite(l) || ((plausible_mask >> i) & 1U) == 0) {
      speed_[static_cast<std::size_t>(i)].Reset();
      length_m_(i) = NAN;
      Trip(i, GuardReason::kReading);
      continue;
    }
    LegSpeedEstimator& speed = speed_[static_cast<std::size_t>(i)];
    speed.Add(utime, l);
    length_m_(i) = l;
    const double v = speed.speed_mps();
    if (std::abs(v) > limits_.speed_cap_mps) Trip(i, GuardReason::kSpeed);
    if (l < limits_.min_length_m + limits_.margin_m && v < -limits_.creep_speed_mps) {
      Trip(i, GuardReason::kRetractedEnd);
    }
    if (l > limits_.max_length_m - limits_.margin_m && v > limits_.creep_speed_mps) {
      Trip(i, GuardReason::kExtendedEnd);
    }
  }
  return static_cast<uint8_t>(tripped_mask_ & ~before);
}

Vector6d LegGuard::Apply(const Vector6d& duty) {
  Vector6d out = Vector6d::Zero();
  limited_mask_ = 0;
  for (int i = 0; i < kNumLegs; ++i) {
    const auto bit = static_cast<uint8_t>(1U << i);
    const double d = std::isfinite(duty(i)) ? duty(i) : 0.0;
    if (tripped_mask_ & bit) {
      // Re-armed by a zero command once the reading is plausible again.
      if (d == 0.0 && (plausible_mask_ & bit) && std::isfinite(length_m_(i))) {
        tripped_mask_ = static_cast<uint8_t>(tripped_mask_ & ~bit);
        reason_[static_cast<std::size_t>(i)] = GuardReason::kNone;
      } else if (d != 0.0) {
        limited_mask_ |= bit;
      }
      continue;
    }
    const double l = length_m_(i);
    const bool near_retracted = !(l >= limits_.min_length_m + limits_.margin_m);
    const bool near_extended = !(l <= limits_.max_length_m - limits_.margin_m);
    if ((near_retracted && d < 0.0) || (near_extended && d > 0.0)) {
      limited_mask_ |= bit;
      continue;
    }
    out(i) = d;
  }
  return out;
}

}  // namespace stewart::hw
