#pragma once
// The leg-space guard of bring-up (docs/hardware.md, "Identify the
// actuators"). During bring-up nothing of the stack is in the loop: no
// estimator, no safety filter. A program drives the legs' PWM duty directly,
// so the leg readings themselves must stop a leg that comes near a stroke end
// or moves faster than it can under its motor alone (a wrong drive sign, a
// broken pot, a runaway program). hw_bridge's bring-up mode applies it to its
// own readings, the identification procedure (identify/) to the samples it
// receives: two guards, one rule.
//
// Per leg, on every sample:
//   - end zone: L < l_min + margin or L > l_max - margin: duty towards that
//     end is zeroed; duty away from it is allowed, unless the leg moves
//     towards the end faster than creep_speed_mps (a reversed motor):
//     then the leg trips;
//   - speed: |Ld| > speed_cap_mps trips the leg;
//   - reading: a non-finite or implausible reading trips the leg.
// A tripped leg gets zero duty until it is re-armed by a zero duty command
// for it (Apply) with a plausible reading; the first reason is kept.
// In normal operation the bridge's last-line guard (guard/actuator_guard.h)
// watches the legs instead, with the same speed estimate.
#include <array>
#include <cstdint>

#include "stewart/common/enum_table.h"
#include "stewart/guard/leg_speed_estimator.h"
#include "stewart/model/types.h"

namespace stewart::hw {

struct LegGuardLimits {
  double min_length_m = 0.0;  ///< stroke ends (joint to joint)
  double max_length_m = 0.0;
  double margin_m = 0.005;        ///< end zone width
  double speed_cap_mps = 0.05;    ///< |Ld| above this trips
  double creep_speed_mps = 2e-3;  ///< in the end zone, towards the end, above this trips
};

enum class GuardReason : uint8_t {
  kNone,
  kRetractedEnd,  ///< moved towards the retracted end inside its zone
  kExtendedEnd,   ///< moved towards the extended end inside its zone
  kSpeed,         ///< faster than the cap
  kReading,       ///< non-finite or implausible reading
};
inline constexpr EnumTable<GuardReason, 5> kGuardReasonNames{{{
    {GuardReason::kNone, "none"},
    {GuardReason::kRetractedEnd, "retracted_end"},
    {GuardReason::kExtendedEnd, "extended_end"},
    {GuardReason::kSpeed, "speed_cap"},
    {GuardReason::kReading, "bad_reading"},
}}};
inline const char* ToString(GuardReason reason) { return kGuardReasonNames.Name(reason).data(); }

class LegGuard {
 public:
  explicit LegGuard(const LegGuardLimits& limits) : limits_(limits) {}

  /// A new sample: lengths (m) and which legs' readings are plausible
  /// (bit i). Updates the speeds and trips legs; returns the legs that
  /// tripped on this sample (bit i).
  uint8_t Update(int64_t utime, const Vector6d& leg_length_m, uint8_t plausible_mask = 0x3F);

  /// The duty a leg may get now (positive extends): zero for a tripped leg,
  /// zero towards the near end inside an end zone. A zero duty for a tripped
  /// leg with a plausible reading re-arms it. Non-finite duty is zero.
  Vector6d Apply(const Vector6d& duty);

  uint8_t tripped_mask() const { return tripped_mask_; }
  /// Legs whose duty Apply changed on its last call (tripped or end zone).
  uint8_t limited_mask() const { return limited_mask_; }
  GuardReason reason(int leg) const { return reason_[static_cast<std::size_t>(leg)]; }
  double speed_mps(int leg) const { return speed_[static_cast<std::size_t>(leg)].speed_mps(); }
  double length_m(int leg) const { return length_m_(leg); }
  const LegGuardLimits& limits() const { return limits_; }

 private:
  void Trip(int leg, GuardReason reason);

  LegGuardLimits limits_;
  std::array<LegSpeedEstimator, kNumLegs> speed_{};
  std::array<GuardReason, kNumLegs> reason_{};
  Vector6d length_m_ = Vector6d::Constant(NAN);
  uint8_t plausible_mask_ = 0;
  uint8_t tripped_mask_ = 0;
  uint8_t limited_mask_ = 0;
};

}  // namespace stewart::hw
