#pragma once
// Measurement models h(x) of the EKF and their Jacobians dh/dx, for the state
// layout of ekf_types.h. Each equation is the model's (kinematics.h, imu.h);
// only the Jacobian bookkeeping lives here.
#include "stewart/estimator/ekf_types.h"
#include "stewart/model/platform_params.h"

namespace stewart {

template <int M>
using MeasurementJacobian = Eigen::Matrix<double, M, kEkfStateSize>;

/// Leg lengths L(q) by inverse kinematics (paper eq. 1); dL/dq = J_l, so no
/// forward-kinematics solve is needed in the update.
void PredictLegLengths(const PlatformParams& params, const EkfVector& x, Vector6d* leg_length_m,
                       MeasurementJacobian<6>* jacobian);

/// Gyro: omega_P = R^T E(r) rd + b_g (rad/s, {P}).
void PredictGyro(const EkfVector& x, Vector3d* gyro_radps, MeasurementJacobian<3>* jacobian);

/// d(specific force)/d(qdd) at (q, qd) (3x6; the specific force is affine in qdd).
Eigen::Matrix<double, 3, 6> AccelQddJacobian(const EkfVector& x, const Vector6d& qdd,
                                             const Vector3d& imu_offset_in_P_m,
                                             double gravity_mps2);

/// Accelerometer: specific force at the IMU, {P} (m/s^2), given the
/// predicted qdd. The Jacobian holds qdd fixed (docs/estimator.md); with the
/// dynamics process model the EKF adds AccelQddJacobian * dqdd/dx.
void PredictAccel(const EkfVector& x, const Vector6d& qdd, const Vector3d& imu_offset_in_P_m,
                  double gravity_mps2, Vector3d* accel_mps2, MeasurementJacobian<3>* jacobian);

/// Wraps an angle difference to (-pi, pi].
double WrapAngle(double angle_rad);

}  // namespace stewart
