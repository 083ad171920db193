#include "stewart/model/imu.h"

#include "stewart/model/rotation.h"

namespace stewart {

Vector3d BodyAngularVelocity(const Vector6d& q, const Vector6d& qd) {
  const Vector3d rpy = q.tail<3>();
  return RotationFromEuler(rpy).transpose() * (EulerRateMatrix(rpy) * qd.tail<3>());
}

Vector3d ImuSpecificForce(const Vector6d& q, const Vector6d& qd, const Vector6d& qdd,
                          const Vector3d& imu_offset_in_P_m, double gravity_mps2) {
  const Vector3d rpy = q.tail<3>();
  const Matrix3d R = RotationFromEuler(rpy);
  const Matrix3d E = EulerRateMatrix(rpy);
  const Vector3d omega = E * qd.tail<3>();
  const Vector3d alpha = E * qdd.tail<3>() + EulerRateBiasAcceleration(rpy, qd.tail<3>());
  const Vector3d r = R * imu_offset_in_P_m;
  const Vector3d a_imu = qdd.head<3>() + alpha.cross(r) + omega.cross(omega.cross(r));
  return R.transpose() * (a_imu + Vector3d(0.0, 0.0, gravity_mps2));
}

}  // namespace stewart
