#include "stewart/model/rotation.h"

#include <algorithm>
#include <cmath>

namespace stewart {

Matrix3d RotationFromEuler(const Vector3d& rpy_rad) {
  const double cf = std::cos(rpy_rad.x()), sf = std::sin(rpy_rad.x());
  const double ct = std::cos(rpy_rad.y()), st = std::sin(rpy_rad.y());
  const double cp = std::cos(rpy_rad.z()), sp = std::sin(rpy_rad.z());
  Matrix3d R;
  R << cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf,  //
      sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf,   //
      -st, ct * sf, ct * cf;
  return R;
}

Matrix3d EulerRateMatrix(const Vector3d& rpy_rad) {
  const double ct = std::cos(rpy_rad.y()), st = std::sin(rpy_rad.y());
  const double cp = std::cos(rpy_rad.z()), sp = std::sin(rpy_rad.z());
  Matrix3d E;
  E << cp * ct, -sp, 0.0,  //
      sp * ct, cp, 0.0,    //
      -st, 0.0, 1.0;
  return E;
}

Vector3d EulerRateBiasAcceleration(const Vector3d& rpy_rad, const Vector3d& rpy_rate_radps) {
  const double ct = std::cos(rpy_rad.y()), st = std::sin(rpy_rad.y());
  const double cp = std::cos(rpy_rad.z()), sp = std::sin(rpy_rad.z());
  const double fd = rpy_rate_radps.x(), td = rpy_rate_radps.y(), pd = rpy_rate_radps.z();
  // d/dt of E's first two columns; the third is constant.
  const Vector3d dcol0(-cp * st * td - sp * ct * pd, -sp * st * td + cp * ct * pd, -ct * td);
  const Vector3d dcol1(-cp * pd, -sp * pd, 0.0);
  return fd * dcol0 + td * dcol1;
}

Vector3d EulerFromRotation(const Matrix3d& R) {
  const double theta = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double phi = std::atan2(R(2, 1), R(2, 2));
  const double psi = std::atan2(R(1, 0), R(0, 0));
  return Vector3d(phi, theta, psi);
}

}  // namespace stewart
