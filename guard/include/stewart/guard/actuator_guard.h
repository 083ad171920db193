#pragma once
// The actuators' last line of defence (docs/operations.md, "Trust model",
// "The actuator guard"): plant_sim and hw_bridge watch the legs on their own
// readings, independently of the estimator, the controller and the safety
// filter, and cut the drive when one of them
//   - reads closer than stroke_margin_m to a stroke end (or is implausible),
//   - moves faster than speed_cap_mps (a least-squares slope of its
//     readings, leg_speed_estimator.h),
//   - is commanded a force beyond force_limit_n in magnitude (or non-finite).
// A trip latches: the drive stays off (the P-16P's lead screws hold the legs)
// until an operator RESET finds every reading back inside, every speed
// within the cap (Reset). The first trip's reason is kept for the report.
// No allocation; Describe() builds the health message, on a trip only.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "stewart/common/enum_table.h"
#include "stewart/guard/leg_speed_estimator.h"
#include "stewart/model/types.h"

namespace stewart {

struct ActuatorGuardLimits {
  double min_length_m = 0.0;  ///< the stroke ends, joint to joint (m)
  double max_length_m = 0.0;
  double stroke_margin_m = 0.005;  ///< readings stay this far inside the ends (m)
  double speed_cap_mps = 0.3;      ///< |leg speed| above this trips (m/s)
  double force_limit_n = 20.0;     ///< |commanded leg force| above this trips (N)
};

enum class GuardTripReason : uint8_t {
  kNone,
  kRetractedEnd,  ///< a leg within the margin of its retracted end
  kExtendedEnd,   ///< ... of its extended end
  kSpeed,         ///< faster than the cap
  kForce,         ///< a commanded force beyond the bound
  kReading,       ///< a non-finite or implausible reading
};
inline constexpr EnumTable<GuardTripReason, 6> kGuardTripReasonNames{{{
    {GuardTripReason::kNone, "none"},
    {GuardTripReason::kRetractedEnd, "retracted_end"},
    {GuardTripReason::kExtendedEnd, "extended_end"},
    {GuardTripReason::kSpeed, "speed_cap"},
    {GuardTripReason::kForce, "force_bound"},
    {GuardTripReason::kReading, "bad_reading"},
}}};
inline const char* ToString(GuardTripReason r) { return kGuardTripReasonNames.Name(r).data(); }

/// The first trip since the guard was last cleared.
struct GuardTrip {
  GuardTripReason reason = GuardTripReason::kNone;
  int leg = -1;
  double value = 0.0;  ///< the length (m), speed (m/s) or force (N) that crossed
  int64_t utime = 0;   ///< sample time of the readings it tripped on
};

enum class GuardResetResult : uint8_t {
  kCleared,          ///< the latch is open, the drive may be applied again
  kNotTripped,       ///< nothing to clear
  kReadingsOutside,  ///< refused: a reading is still outside (or no speed estimate yet)
};
inline constexpr EnumTable<GuardResetResult, 3> kGuardResetResultNames{{{
    {GuardResetResult::kCleared, "cleared"},
    {GuardResetResult::kNotTripped, "not_tripped"},
    {GuardResetResult::kReadingsOutside, "readings_outside"},
}}};
inline const char* ToString(GuardResetResult r) { return kGuardResetResultNames.Name(r).data(); }

/// The guard's force rule: a leg force command (N) beyond `force_limit_n` in
/// magnitude, or NaN, trips it (the drive goes off instead of applying it).
inline bool ForceBeyondGuardBound(double force_n, double force_limit_n) {
  return !(std::abs(force_n) <= force_limit_n);
}
/// The same rule over all legs (the estimator models the guard with it).
inline bool AnyForceBeyondGuardBound(const Vector6d& force_n, double force_limit_n) {
  for (int i = 0; i < force_n.size(); ++i) {
    if (ForceBeyondGuardBound(force_n(i), force_limit_n)) return true;
  }
  return false;
}

class ActuatorGuard {
 public:
  /// Throws std::logic_error on inconsistent limits (margins that leave no
  /// stroke, non-positive caps).
  explicit ActuatorGuard(const ActuatorGuardLimits& limits);

  /// A new sample of the actuator's own leg readings at `utime` (us);
  /// `plausible_mask` bit i: leg i's reading is plausible (a pot in its
  /// calibrated span). Returns true when the guard tripped on it.
  bool OnReadings(int64_t utime, const Vector6d& leg_length_m, uint8_t plausible_mask = 0x3F);
  /// A force command about to be applied (N). Returns true when the guard
  /// tripped on it.
  bool OnForceCommand(const Vector6d& force_n);

  /// Latched: the drive must be off.
  bool tripped() const { return trip_.reason != GuardTripReason::kNone; }
  const GuardTrip& trip() const { return trip_; }
  /// The operator's RESET: clears the latch only if every leg reads inside
  /// its margins, plausibly, with a full speed window within the cap.
  GuardResetResult Reset();
  /// The readings are back inside: what Reset requires.
  bool ReadingsInside() const;

  /// "leg 2 speed 0.31 m/s above the cap 0.05 m/s" (allocates: on a trip only).
  std::string Describe() const;

  const ActuatorGuardLimits& limits() const { return limits_; }
  double speed_mps(int leg) const { return speed_[static_cast<std::size_t>(leg)].speed_mps(); }
  int64_t trips() const { return trips_; }
  int64_t resets_cleared() const { return resets_cleared_; }
  int64_t resets_refused() const { return resets_refused_; }
  /// The worst approach seen since construction, for sizing the limits:
  /// smallest distance of any reading to a stroke end (m), largest |speed|
  /// (m/s) and |force| (N).
  double min_end_distance_m() const { return min_end_distance_m_; }
  double max_speed_mps() const { return max_speed_mps_; }
  double max_force_n() const { return max_force_n_; }

 private:
  bool Trip(GuardTripReason reason, int leg, double value);

  ActuatorGuardLimits limits_;
  std::array<LegSpeedEstimator, kNumLegs> speed_{};
  Vector6d length_m_ = Vector6d::Constant(NAN);
  uint8_t plausible_mask_ = 0;
  int64_t utime_ = 0;
  GuardTrip trip_;
  int64_t trips_ = 0;
  int64_t resets_cleared_ = 0;
  int64_t resets_refused_ = 0;
  double min_end_distance_m_ = 1e9;
  double max_speed_mps_ = 0.0;
  double max_force_n_ = 0.0;
};

}  // namespace stewart
