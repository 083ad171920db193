#include "stewart/estimator/measurement_models.h"

#include <cmath>

#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"
#include "stewart/model/rotation.h"

namespace stewart {
namespace {

// Central-difference step: the functions are smooth, O(1) in the angles, and
// the truncation error ~h^2 is far below the sensor noise.
constexpr double kFdStep = 1e-6;

// Fills dh/dx for the state entries [first, first+count) by central
// differences of `h` (any callable EkfVector -> Vector3d).
template <typename Fn>
void CentralDifference(const EkfVector& x, int first, int count, Fn h,
                       MeasurementJacobian<3>* jacobian) {
  EkfVector xp = x;
  for (int i = first; i < first + count; ++i) {
    xp(i) = x(i) + kFdStep;
    const Vector3d plus = h(xp);
    xp(i) = x(i) - kFdStep;
    const Vector3d minus = h(xp);
    xp(i) = x(i);
    jacobian->col(i) = (plus - minus) / (2.0 * kFdStep);
  }
}

}  // namespace

void PredictLegLengths(const PlatformParams& params, const EkfVector& x, Vector6d* leg_length_m,
                       MeasurementJacobian<6>* jacobian) {
  const Vector6d q = x.segment<6>(kEkfQ);
  const LegGeometry legs = ComputeLegGeometry(params, q);
  *leg_length_m = legs.length_m;
  jacobian->setZero();
  jacobian->block<6, 6>(0, kEkfQ) = LegLengthJacobian(legs, q.tail<3>());
}

void PredictGyro(const EkfVector& x, Vector3d* gyro_radps, MeasurementJacobian<3>* jacobian) {
  const auto h = [](const EkfVector& s) -> Vector3d {
    return BodyAngularVelocity(s.segment<6>(kEkfQ), s.segment<6>(kEkfQd)) +
           s.segment<3>(kEkfGyroBias);
  };
  *gyro_radps = h(x);
  jacobian->setZero();
  const Vector3d rpy = x.segment<3>(kEkfQ + 3);
  // Linear in the Euler rates and the bias: exact blocks.
  jacobian->block<3, 3>(0, kEkfQd + 3) = RotationFromEuler(rpy).transpose() * EulerRateMatrix(rpy);
  jacobian->block<3, 3>(0, kEkfGyroBias).setIdentity();
  CentralDifference(x, kEkfQ + 3, 3, h, jacobian);
}

void PredictAccel(const EkfVector& x, const Vector6d& qdd, const Vector3d& imu_offset_in_P_m,
                  double gravity_mps2, Vector3d* accel_mps2, MeasurementJacobian<3>* jacobian) {
  const auto h = [&](const EkfVector& s) -> Vector3d {
    return ImuSpecificForce(s.segment<6>(kEkfQ), s.segment<6>(kEkfQd), qdd, imu_offset_in_P_m,
                            gravity_mps2);
  };
  *accel_mps2 = h(x);
  jacobian->setZero();
  // With qdd held, the specific force depends on the angles (gravity
  // direction, lever arm) and the angular rates (centripetal term) only.
  CentralDifference(x, kEkfQ + 3, 3, h, jacobian);
  CentralDifference(x, kEkfQd + 3, 3, h, jacobian);
}

Eigen::Matrix<double, 3, 6> AccelQddJacobian(const EkfVector& x, const Vector6d& qdd,
                                             const Vector3d& imu_offset_in_P_m,
                                             double gravity_mps2) {
  Eigen::Matrix<double, 3, 6> d;
  const Vector6d q = x.segment<6>(kEkfQ), qd = x.segment<6>(kEkfQd);
  // Affine in qdd: a unit difference is exact.
  const Vector3d base = ImuSpecificForce(q, qd, qdd, imu_offset_in_P_m, gravity_mps2);
  for (int i = 0; i < 6; ++i) {
    Vector6d e = qdd;
    e(i) += 1.0;
    d.col(i) = ImuSpecificForce(q, qd, e, imu_offset_in_P_m, gravity_mps2) - base;
  }
  return d;
}

double WrapAngle(double angle_rad) { return std::remainder(angle_rad, 2.0 * M_PI); }

}  // namespace stewart
