#pragma once
// IMU measurement equations, shared by the simulator (which generates the
// readings) and the estimator (which predicts them).
//
// The IMU is rigidly mounted on the platform at `imu_offset_in_P_m` (in {P}),
// its axes aligned with {P}.
#include "stewart/model/types.h"

namespace stewart {

/// Gyro reading without noise or bias: omega in {P} axes (rad/s),
/// omega_P = R^T E(r) rd.
Vector3d BodyAngularVelocity(const Vector6d& q, const Vector6d& qd);

/// Accelerometer reading without noise or bias: specific force in {P} axes
/// (m/s^2), f_P = R^T (a_imu - g_B) with g_B = [0 0 -g] and a_imu the
/// acceleration of the IMU point in {B}.
Vector3d ImuSpecificForce(const Vector6d& q, const Vector6d& qd, const Vector6d& qdd,
                          const Vector3d& imu_offset_in_P_m, double gravity_mps2);

}  // namespace stewart
