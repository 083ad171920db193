#pragma once
// Euler-angle conventions, in one place.
//
// Orientation r = [phi theta psi] (rad), Z-Y-X (yaw-pitch-roll):
//   R = Rz(psi) Ry(theta) Rx(phi),  maps {P} vectors into {B}.
// Angular velocity of {P} in {B} coordinates: omega = E(r) rd,
//   E = [Rz Ry e_x, Rz e_y, e_z]  (singular at theta = +-pi/2).
#include "stewart/model/types.h"

namespace stewart {

/// sin and cos of r = [phi theta psi], computed once: R, E and Edot rd all
/// need them, and sincos is a noticeable part of a model evaluation.
struct EulerAngleTrig {
  explicit EulerAngleTrig(const Vector3d& rpy_rad);
  double sin_phi, cos_phi, sin_theta, cos_theta, sin_psi, cos_psi;
};

/// R = Rz(psi) Ry(theta) Rx(phi) from r = [phi theta psi] (rad).
Matrix3d RotationFromEuler(const Vector3d& rpy_rad);
Matrix3d RotationFromEuler(const EulerAngleTrig& trig);

/// E(r): omega_B = E(r) * rd, with omega in {B} (rad/s).
Matrix3d EulerRateMatrix(const Vector3d& rpy_rad);
Matrix3d EulerRateMatrix(const EulerAngleTrig& trig);

/// Edot(r, rd) * rd: the part of the angular acceleration (rad/s^2, {B})
/// that does not depend on rdd.
Vector3d EulerRateBiasAcceleration(const Vector3d& rpy_rad, const Vector3d& rpy_rate_radps);
Vector3d EulerRateBiasAcceleration(const EulerAngleTrig& trig, const Vector3d& rpy_rate_radps);

/// Edot(r, rd), the time derivative of E (1/s): the matrix itself, for the
/// terms that need Edot^T (the generalised momentum's rate, identification).
Matrix3d EulerRateMatrixDerivative(const EulerAngleTrig& trig, const Vector3d& rpy_rate_radps);

/// Inverse of RotationFromEuler for theta in (-pi/2, pi/2).
Vector3d EulerFromRotation(const Matrix3d& R);

/// Skew-symmetric matrix with Skew(a) * b = a x b.
inline Matrix3d Skew(const Vector3d& a) {
  Matrix3d s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}

}  // namespace stewart
