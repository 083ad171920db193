#include "stewart/model/kinematics.h"

#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "leg_arrays.h"
#include "stewart/model/rotation.h"

namespace stewart {

LegGeometry ComputeLegGeometry(const PlatformParams& params, const Vector6d& q) {
  const internal::LegArrays arrays =
      internal::ComputeLegArrays(params, RotationFromEuler(q.tail<3>()), q.head<3>());
  LegGeometry legs;
  legs.platform_offset_in_B_m = arrays.offset.matrix();
  legs.unit_in_B = arrays.unit.matrix();
  legs.length_m = arrays.length.transpose();
  return legs;
}

Vector6d InverseKinematics(const PlatformParams& params, const Vector6d& q) {
  return ComputeLegGeometry(params, q).length_m;
}

Matrix6d LegLengthJacobian(const LegGeometry& legs, const Vector3d& rpy_rad) {
  const Matrix3d E = EulerRateMatrix(rpy_rad);
  Matrix6d J;
  for (int i = 0; i < kNumLegs; ++i) {
    const Vector3d n = legs.unit_in_B.col(i);
    J.block<1, 3>(i, 0) = n.transpose();
    J.block<1, 3>(i, 3) = (legs.platform_offset_in_B_m.col(i).cross(n)).transpose() * E;
  }
  return J;
}

Matrix6d LegLengthJacobian(const PlatformParams& params, const Vector6d& q) {
  return LegLengthJacobian(ComputeLegGeometry(params, q), q.tail<3>());
}

ForwardKinematicsResult ForwardKinematics(const PlatformParams& params,
                                          const Vector6d& leg_length_m, const Vector6d& q_guess,
                                          const ForwardKinematicsOptions& options) {
  ForwardKinematicsResult result;
  result.q = q_guess;
  if (!leg_length_m.allFinite() || !q_guess.allFinite()) {
    result.residual_m = std::numeric_limits<double>::infinity();
    return result;
  }
  for (int iter = 0; iter <= options.max_iterations; ++iter) {
    const LegGeometry legs = ComputeLegGeometry(params, result.q);
    const Vector6d error = legs.length_m - leg_length_m;
    result.residual_m = error.cwiseAbs().maxCoeff();
    result.iterations = iter;
    if (!std::isfinite(result.residual_m)) return result;
    if (result.residual_m <= options.tolerance_m) {
      result.converged = true;
      return result;
    }
    if (iter == options.max_iterations) break;
    const Eigen::PartialPivLU<Matrix6d> lu(LegLengthJacobian(legs, result.q.tail<3>()));
    if (!(std::abs(lu.determinant()) > 1e-14)) return result;  // singular pose
    const Vector6d step = lu.solve(error);
    if (!step.allFinite()) return result;
    result.q -= step;
  }
  // Newton converges quadratically; a residual at round-off level after the
  // last step is a converged answer even if below-tolerance was not reached.
  result.converged = result.residual_m <= 1e3 * options.tolerance_m;
  return result;
}

bool LegLengthsWithinStroke(const PlatformParams& params, const Vector6d& leg_length_m) {
  return (leg_length_m.array() >= params.leg_min_length_m).all() &&
         (leg_length_m.array() <= params.leg_max_length_m).all();
}

bool PoseInWorkspace(const PlatformParams& params, const Vector6d& q, double max_tilt_rad) {
  if (!q.allFinite()) return false;
  if (std::abs(q(4)) >= max_tilt_rad || std::abs(q(3)) >= max_tilt_rad) return false;
  if (q(2) <= 0.0) return false;
  return LegLengthsWithinStroke(params, InverseKinematics(params, q));
}

}  // namespace stewart
