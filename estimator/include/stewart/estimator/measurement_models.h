#pragma once
// Measurement models h(x) of the EKF and their Jacobians dh/dx, for the state
// layout of ekf_types.h. Each equation is the model's (kinematics.h, imu.h);
// the Jacobians are analytic (docs/estimator.md). The filter uses the compact
// forms (only the non-zero blocks); the MeasurementJacobian forms fill the
// whole row block, for tests and tools.
#include "stewart/estimator/ekf_types.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/rotation.h"

namespace stewart {

template <int M>
using MeasurementJacobian = Eigen::Matrix<double, M, kEkfStateSize>;

/// Leg lengths L(q) by inverse kinematics (paper eq. 1); dL/dq = J_l, so no
/// forward-kinematics solve is needed in the update.
/// Compact form: `trig` holds the sines and cosines of q's angles.
void PredictLegLengths(const PlatformParams& params, const Vector6d& q, const EulerAngleTrig& trig,
                       Vector6d* leg_length_m, Matrix6d* dlength_dq);
void PredictLegLengths(const PlatformParams& params, const EkfVector& x, Vector6d* leg_length_m,
                       MeasurementJacobian<6>* jacobian);

/// Gyro: omega_P = R^T E(r) rd + b_g (rad/s, {P}). Compact form (`trig` of
/// the Euler angles): the blocks for the angles and their rates (the bias
/// block is the identity).
void PredictGyro(const EulerAngleTrig& trig, const Vector6d& qd, const Vector3d& bias,
                 Vector3d* gyro_radps, Matrix3d* dgyro_dangles, Matrix3d* dgyro_drates);
void PredictGyro(const EkfVector& x, Vector3d* gyro_radps, MeasurementJacobian<3>* jacobian);

/// The non-zero blocks of the accelerometer's Jacobians.
struct AccelJacobians {
  Matrix3d d_angles;  ///< d f / d[phi theta psi], qdd held
  Matrix3d d_rates;   ///< d f / d[phid thetad psid], qdd held
  Matrix36d d_qdd;    ///< d f / d qdd (f is affine in qdd)
};

/// Accelerometer: specific force at the IMU, {P} (m/s^2), given the
/// predicted qdd. The state Jacobian holds qdd fixed (docs/estimator.md); with
/// the dynamics process model the EKF adds d_qdd * dqdd/dx to the noise.
/// Compact form: `trig` of the Euler angles; `jacobians` may be null.
void PredictAccel(const EulerAngleTrig& trig, const Vector6d& qd, const Vector6d& qdd,
                  const Vector3d& imu_offset_in_P_m, double gravity_mps2, Vector3d* accel_mps2,
                  AccelJacobians* jacobians);
void PredictAccel(const EkfVector& x, const Vector6d& qdd, const Vector3d& imu_offset_in_P_m,
                  double gravity_mps2, Vector3d* accel_mps2, MeasurementJacobian<3>* jacobian);

/// d(specific force)/d(qdd) at (q, qd) (3x6; the specific force is affine in qdd).
Eigen::Matrix<double, 3, 6> AccelQddJacobian(const EkfVector& x, const Vector6d& qdd,
                                             const Vector3d& imu_offset_in_P_m,
                                             double gravity_mps2);

/// Wraps an angle difference to (-pi, pi].
double WrapAngle(double angle_rad);

}  // namespace stewart
