#include "stewart/hw_bridge/leg_guard.h"

#include <cmath>

namespace stewart::hw {

void LegSpeedEstimator::Add(int64_t utime, double length_m) {
  if (count_ > 0) {
    const int last = (next_ + kWindow - 1) % kWindow;
    const int64_t gap = utime - utime_[static_cast<std::size_t>(last)];
    if (gap <= 0 || gap > kMaxGapUs) count_ = 0;
  }
  utime_[static_cast<std::size_t>(next_)] = utime;
  length_m_[static_cast<std::size_t>(next_)] = length_m;
  next_ = (next_ + 1) % kWindow;
  if (count_ < kWindow) ++count_;
  // A full window only: over a few samples one ADC step of a leg at rest
  // reads as a speed (0.2 mm in 4 ms is 50 mm/s).
  if (count_ < kWindow) {
    speed_mps_ = 0.0;
    return;
  }
  // Slope of length over time, both relative to the newest reading (keeps
  // the sums small and exact enough in double).
  const int newest = (next_ + kWindow - 1) % kWindow;
  const int64_t t0 = utime_[static_cast<std::size_t>(newest)];
  const double l0 = length_m_[static_cast<std::size_t>(newest)];
  double st = 0.0, sl = 0.0, stt = 0.0, stl = 0.0;
  for (int k = 0; k < count_; ++k) {
    const auto j = static_cast<std::size_t>((newest + kWindow - k) % kWindow);
    const double t = static_cast<double>(utime_[j] - t0) * 1e-6;
    const double l = length_m_[j] - l0;
    st += t;
    sl += l;
    stt += t * t;
    stl += t * l;
  }
  const double n = count_;
  const double denominator = n * stt - st * st;
  speed_mps_ = denominator > 0.0 ? (n * stl - st * sl) / denominator : 0.0;
}

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
