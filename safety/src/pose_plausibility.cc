#include "stewart/safety/pose_plausibility.h"

#include <cmath>

namespace stewart::safety {

std::uint8_t PoseProblems(const PlatformParams& platform, const Vector6d& q,
                          const Vector6d& leg_length_m) {
  std::uint8_t problems = kPosePlausible;
  // Written as !(x <= bound) so that a NaN is a problem too.
  if (!(std::fabs(q(3)) <= kMaxTiltRad && std::fabs(q(4)) <= kMaxTiltRad)) {
    problems |= kPoseTiltBeyondBound;
  }
  if (!(std::fabs(q(5)) <= kMaxYawRad)) problems |= kPoseYawBeyondBound;
  if (!(q(2) > 0.0)) problems |= kPoseBelowBase;
  const double lowest = platform.leg_min_length_m - kLegStrokeToleranceM;
  const double highest = platform.leg_max_length_m + kLegStrokeToleranceM;
  if (!((leg_length_m.array() >= lowest).all() && (leg_length_m.array() <= highest).all())) {
    problems |= kPoseLegOutsideStroke;
  }
  return problems;
}

}  // namespace stewart::safety
