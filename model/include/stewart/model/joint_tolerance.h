#pragma once
// How far the pose the stack computes can be from the platform's true pose
// when the joint centres are known only within a tolerance.
//
// The estimator fits the pose to the measured leg lengths with the nominal
// joints. A joint centre displaced by delta (in its own frame) changes leg
// i's true length, to first order, by
//     delta L_i = n_i^T (R delta p_i - delta b_i)                (m)
// (n_i the leg's unit vector in {B}, R the platform's attitude), and the
// fitted pose by J_l^-1 delta L. No sensor of the stack sees that error in
// x, y, z or yaw (the accelerometer sees only the tilt), so the safety filter
// keeps a margin of its worst case (docs/safety.md, "Joint tolerance").
#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart {

/// Each joint centre lies within +-radius_m of its nominal radius and within
/// +-angle_rad of its nominal angle on its circle (both frames' joints).
struct JointTolerance {
  double radius_m = 0.0;
  double angle_rad = 0.0;
  bool IsZero() const { return radius_m == 0.0 && angle_rad == 0.0; }
};

/// First-order worst case of |q_fit - q| per pose axis (m for x y z, rad for
/// the Euler angles) at the true pose `q`: every joint anywhere within
/// `tolerance`, q_fit the nominal geometry's pose for the true leg lengths.
/// The worst case takes each leg's length error at its extreme with the sign
/// that adds up on the axis (each leg's four joint coordinates are
/// independent of the other legs'). Infinite where J_l is singular.
Vector6d PoseErrorBound(const PlatformParams& nominal, const JointTolerance& tolerance,
                        const Vector6d& q);

}  // namespace stewart
