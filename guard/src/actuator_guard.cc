#include "stewart/guard/actuator_guard.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "stewart/common/check.h"

namespace stewart {

ActuatorGuard::ActuatorGuard(const ActuatorGuardLimits& limits) : limits_(limits) {
  STEWART_CHECK(limits.stroke_margin_m >= 0.0 &&
                    limits.min_length_m + 2.0 * limits.stroke_margin_m < limits.max_length_m,
                "ActuatorGuard: the stroke margins leave no stroke");
  STEWART_CHECK(limits.speed_cap_mps > 0.0 && limits.force_limit_n > 0.0,
                "ActuatorGuard: the speed cap and the force bound must be positive");
}

bool ActuatorGuard::Trip(GuardTripReason reason, int leg, double value) {
  if (tripped()) return false;  // the first reason is the one to report
  trip_ = GuardTrip{reason, leg, value, utime_};
  ++trips_;
  return true;
}

bool ActuatorGuard::OnReadings(int64_t utime, const Vector6d& leg_length_m,
                               uint8_t plausible_mask) {
  utime_ = utime;
  plausible_mask_ = plausible_mask;
  bool tripped_now = false;
  for (int i = 0; i < kNumLegs; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double l = leg_length_m(i);
    if (!std::isfinite(l) || ((plausible_mask >> i) & 1U) == 0) {
      speed_[k].Reset();
      length_m_(i) = NAN;
      tripped_now |= Trip(GuardTripReason::kReading, i, l);
      continue;
    }
    length_m_(i) = l;
    speed_[k].Add(utime, l);
    const double v = speed_[k].speed_mps();
    min_end_distance_m_ =
        std::min(min_end_distance_m_, std::min(l - limits_.min_length_m, limits_.max_length_m - l));
    max_speed_mps_ = std::max(max_speed_mps_, std::abs(v));
    if (l < limits_.min_length_m + limits_.stroke_margin_m) {
      tripped_now |= Trip(GuardTripReason::kRetractedEnd, i, l);
    } else if (l > limits_.max_length_m - limits_.stroke_margin_m) {
      tripped_now |= Trip(GuardTripReason::kExtendedEnd, i, l);
    }
    if (std::abs(v) > limits_.speed_cap_mps) tripped_now |= Trip(GuardTripReason::kSpeed, i, v);
  }
  return tripped_now;
}

bool ActuatorGuard::OnForceCommand(const Vector6d& force_n) {
  bool tripped_now = false;
  for (int i = 0; i < kNumLegs; ++i) {
    const double f = force_n(i);
    if (ForceBeyondGuardBound(f, limits_.force_limit_n)) {
      tripped_now |= Trip(GuardTripReason::kForce, i, f);
    } else {
      max_force_n_ = std::max(max_force_n_, std::abs(f));
    }
  }
  return tripped_now;
}

bool ActuatorGuard::ReadingsInside() const {
  for (int i = 0; i < kNumLegs; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double l = length_m_(i);
    if (((plausible_mask_ >> i) & 1U) == 0 || !std::isfinite(l)) return false;
    if (l < limits_.min_length_m + limits_.stroke_margin_m ||
        l > limits_.max_length_m - limits_.stroke_margin_m) {
      return false;
    }
    // A fresh window reads 0: not evidence that the leg is at rest.
    if (!speed_[k].valid() || std::abs(speed_[k].speed_mps()) > limits_.speed_cap_mps) {
      return false;
    }
  }
  return true;
}

GuardResetResult ActuatorGuard::Reset() {
  if (!tripped()) return GuardResetResult::kNotTripped;
  if (!ReadingsInside()) {
    ++resets_refused_;
    return GuardResetResult::kReadingsOutside;
  }
  trip_ = GuardTrip{};
  ++resets_cleared_;
  return GuardResetResult::kCleared;
}

std::string ActuatorGuard::Describe() const {
  if (!tripped()) return "";
  std::ostringstream s;
  s << "leg " << trip_.leg << " ";
  switch (trip_.reason) {
    case GuardTripReason::kRetractedEnd:
      s << "length " << trip_.value << " m within " << limits_.stroke_margin_m
        << " m of the retracted end " << limits_.min_length_m << " m";
      break;
    case GuardTripReason::kExtendedEnd:
      s << "length " << trip_.value << " m within " << limits_.stroke_margin_m
        << " m of the extended end " << limits_.max_length_m << " m";
      break;
    case GuardTripReason::kSpeed:
      s << "speed " << trip_.value << " m/s above the cap " << limits_.speed_cap_mps << " m/s";
      break;
    case GuardTripReason::kForce:
      s << "commanded force " << trip_.value << " N beyond the bound " << limits_.force_limit_n
        << " N";
      break;
    case GuardTripReason::kReading:
      s << "reading implausible (" << trip_.value << " m)";
      break;
    case GuardTripReason::kNone:
      break;
  }
  return s.str();
}

}  // namespace stewart
