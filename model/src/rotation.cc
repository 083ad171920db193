#include "stewart/model/rotation.h"

#include <algorithm>
#include <cmath>

namespace stewart {

EulerAngleTrig::EulerAngleTrig(const Vector3d& rpy_rad)
    : sin_phi(std::sin(rpy_rad.x())),
      cos_phi(std::cos(rpy_rad.x())),
      sin_theta(std::sin(rpy_rad.y())),
      cos_theta(std::cos(rpy_rad.y())),
      sin_psi(std::sin(rpy_rad.z())),
      cos_psi(std::cos(rpy_rad.z())) {}

Matrix3d RotationFromEuler(const EulerAngleTrig& trig) {
  const double cf = trig.cos_phi, sf = trig.sin_phi;
  const double ct = trig.cos_theta, st = trig.sin_theta;
  const double cp = trig.cos_psi, sp = trig.sin_psi;
  Matrix3d R;
  R << cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf,  //
      sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf,   //
      -st, ct * sf, ct * cf;
  return R;
}

Matrix3d RotationFromEuler(const Vector3d& rpy_rad) {
  return RotationFromEuler(EulerAngleTrig(rpy_rad));
}

Matrix3d EulerRateMatrix(const EulerAngleTrig& trig) {
  const double ct = trig.cos_theta, st = trig.sin_theta;
  const double cp = trig.cos_psi, sp = trig.sin_psi;
  Matrix3d E;
  E << cp * ct, -sp, 0.0,  //
      sp * ct, cp, 0.0,    //
      -st, 0.0, 1.0;
  return E;
}

Matrix3d EulerRateMatrix(const Vector3d& rpy_rad) {
  return EulerRateMatrix(EulerAngleTrig(rpy_rad));
}

Vector3d EulerRateBiasAcceleration(const EulerAngleTrig& trig, const Vector3d& rpy_rate_radps) {
  const double ct = trig.cos_theta, st = trig.sin_theta;
  const double cp = trig.cos_psi, sp = trig.sin_psi;
  const double fd = rpy_rate_radps.x(), td = rpy_rate_radps.y(), pd = rpy_rate_radps.z();
  // d/dt of E's first two columns; the third is constant.
  const Vector3d dcol0(-cp * st * td - sp * ct * pd, -sp * st * td + cp * ct * pd, -ct * td);
  const Vector3d dcol1(-cp * pd, -sp * pd, 0.0);
  return fd * dcol0 + td * dcol1;
}

Matrix3d EulerRateMatrixDerivative(const EulerAngleTrig& trig, const Vector3d& rpy_rate_radps) {
  const double ct = trig.cos_theta, st = trig.sin_theta;
  const double cp = trig.cos_psi, sp = trig.sin_psi;
  const double td = rpy_rate_radps.y(), pd = rpy_rate_radps.z();
  Matrix3d Ed;
  Ed << -cp * st * td - sp * ct * pd, -cp * pd, 0.0,  //
      -sp * st * td + cp * ct * pd, -sp * pd, 0.0,    //
      -ct * td, 0.0, 0.0;
  return Ed;
}

Vector3d EulerRateBiasAcceleration(const Vector3d& rpy_rad, const Vector3d& rpy_rate_radps) {
  return EulerRateBiasAcceleration(EulerAngleTrig(rpy_rad), rpy_rate_radps);
}

Vector3d EulerFromRotation(const Matrix3d& R) {
  const double theta = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double phi = std::atan2(R(2, 1), R(2, 2));
  const double psi = std::atan2(R(1, 0), R(0, 0));
  return Vector3d(phi, theta, psi);
}

}  // namespace stewart
