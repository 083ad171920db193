#include "stewart/model/joint_tolerance.h"

#include <cmath>
#include <limits>

#include "stewart/model/kinematics.h"
#include "stewart/model/linear_algebra6.h"
#include "stewart/model/rotation.h"

namespace stewart {
namespace {

// The largest |n^T M delta| over a joint displacement delta within the
// tolerance: radial +-radius_m, tangential +-r angle_rad (the joints lie in
// their frame's xy plane; a joint on the axis has no radial direction and
// its tolerance is then a disc of radius_m).
double LargestLengthChange(const Vector3d& n_in_joint_frame, const Vector3d& joint_m,
                           const JointTolerance& tolerance) {
  const double r = joint_m.head<2>().norm();
  if (!(r > 0.0)) return n_in_joint_frame.head<2>().norm() * tolerance.radius_m;
  const Vector3d radial(joint_m(0) / r, joint_m(1) / r, 0.0);
  const Vector3d tangential(-radial(1), radial(0), 0.0);
  return std::fabs(n_in_joint_frame.dot(radial)) * tolerance.radius_m +
         std::fabs(n_in_joint_frame.dot(tangential)) * r * tolerance.angle_rad;
}

}  // namespace

Vector6d PoseErrorBound(const PlatformParams& nominal, const JointTolerance& tolerance,
                        const Vector6d& q) {
  if (tolerance.IsZero()) return Vector6d::Zero();
  const LegGeometry legs = ComputeLegGeometry(nominal, q);
  const Matrix3d R = RotationFromEuler(q.tail<3>());
  Vector6d largest_length_change_m;
  for (int i = 0; i < kNumLegs; ++i) {
    const Vector3d n = legs.unit_in_B.col(i);
    largest_length_change_m(i) =
        LargestLengthChange(n, nominal.base_joints_in_B_m.col(i), tolerance) +
        LargestLengthChange(R.transpose() * n, nominal.platform_joints_in_P_m.col(i), tolerance);
  }
  Matrix6d inverse = Matrix6d::Identity();
  if (!SolvePartialPivot6(LegLengthJacobian(legs, q.tail<3>()), &inverse)) {
    return Vector6d::Constant(std::numeric_limits<double>::infinity());
  }
  return inverse.cwiseAbs() * largest_length_change_m;
}

}  // namespace stewart
