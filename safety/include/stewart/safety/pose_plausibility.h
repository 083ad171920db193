#pragma once
// Whether a state's pose is one the platform can be in (docs/safety.md,
// "Implausible poses"). The filter's barriers, metric and safe stop all
// evaluate the model at the pose; at a pose the platform cannot take (an
// angle of 1e300 rad, a tilt past the Euler parametrisation's singularity,
// legs beyond the actuators' stroke) those numbers are finite but mean
// nothing, so such a state is rejected as invalid input, never filtered.
#include <cstdint>

#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart::safety {

/// |phi|, |theta| above this (rad) are rejected: the Euler rate matrix E(r)
/// is singular at |theta| = pi/2, and with it H = J_l^T; the model's own
/// workspace (PoseInWorkspace) stops at the same 1 rad.
constexpr double kMaxTiltRad = 1.0;
/// |psi| above this (rad) is rejected: 1e300 rad is a finite number whose
/// sine is not an orientation anyone estimated, and at psi = +-pi/2 the legs
/// are in a singular configuration (H singular with every leg inside its
/// stroke: cond(H) 1e17 at home height).
constexpr double kMaxYawRad = 1.0;
/// A leg may read this far beyond either stroke end (m) before the pose is
/// rejected: the estimator accepts leg readings that far out
/// (estimator.leg_range_margin_m, 0.01 m shipped), so an estimate at an
/// end stop with noise is still a pose.
constexpr double kLegStrokeToleranceM = 0.01;

/// Why a pose was rejected (0: plausible). One bit per reason.
enum PoseProblem : std::uint8_t {
  kPosePlausible = 0,
  kPoseTiltBeyondBound = 1,  ///< |phi| or |theta| > kMaxTiltRad
  kPoseYawBeyondBound = 2,   ///< |psi| > kMaxYawRad
  kPoseBelowBase = 4,        ///< z <= 0: the platform is not above the base
  kPoseLegOutsideStroke = 8  ///< a leg length beyond a stroke end + tolerance
};

/// The problems of pose q (finite) with leg lengths leg_length_m (the
/// inverse kinematics at q, as in DynamicsTerms); kPosePlausible if none.
/// A non-finite leg length counts as outside the stroke.
std::uint8_t PoseProblems(const PlatformParams& platform, const Vector6d& q,
                          const Vector6d& leg_length_m);

}  // namespace stewart::safety
