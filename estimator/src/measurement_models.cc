#include "stewart/estimator/measurement_models.h"

#include <cmath>

#include "stewart/model/rotation.h"

namespace stewart {
namespace {

// E_b(phi, theta) = R^T E: body rates omega_P = E_b rd (Z-Y-X Euler angles;
// independent of psi), and its derivatives by phi (X_phi) and theta (X_theta):
//   E_b = [[1, 0, -st], [0, cf, sf ct], [0, -sf, cf ct]].
struct BodyRateMatrix {
  explicit BodyRateMatrix(const EulerAngleTrig& t)
      : sf(t.sin_phi), cf(t.cos_phi), st(t.sin_theta), ct(t.cos_theta) {}
  Vector3d Times(const Vector3d& w) const {
    return Vector3d(w.x() - st * w.z(), cf * w.y() + sf * ct * w.z(),
                    -sf * w.y() + cf * ct * w.z());
  }
  Matrix3d Matrix() const {
    Matrix3d e;
    e << 1.0, 0.0, -st, 0.0, cf, sf * ct, 0.0, -sf, cf * ct;
    return e;
  }
  Matrix3d DPhi() const {
    Matrix3d x;
    x << 0.0, 0.0, 0.0, 0.0, -sf, cf * ct, 0.0, -cf, -sf * ct;
    return x;
  }
  Matrix3d DTheta() const {
    Matrix3d x;
    x << 0.0, 0.0, -ct, 0.0, 0.0, -sf * st, 0.0, 0.0, -cf * st;
    return x;
  }
  // X_phi w and X_theta w.
  Vector3d DPhiTimes(const Vector3d& w) const {
    return Vector3d(0.0, -sf * w.y() + cf * ct * w.z(), -cf * w.y() - sf * ct * w.z());
  }
  Vector3d DThetaTimes(const Vector3d& w) const {
    return Vector3d(-ct * w.z(), -sf * st * w.z(), -cf * st * w.z());
  }
  // Second derivatives times w: X_phi,phi w, X_phi,theta w, X_theta,theta w.
  Vector3d DPhiPhiTimes(const Vector3d& w) const {
    return Vector3d(0.0, -cf * w.y() - sf * ct * w.z(), sf * w.y() - cf * ct * w.z());
  }
  Vector3d DPhiThetaTimes(const Vector3d& w) const {
    return Vector3d(0.0, -cf * st * w.z(), sf * st * w.z());
  }
  Vector3d DThetaThetaTimes(const Vector3d& w) const {
    return Vector3d(st * w.z(), -sf * ct * w.z(), -cf * ct * w.z());
  }
  double sf, cf, st, ct;
};

}  // namespace

void PredictLegLengths(const PlatformParams& params, const Vector6d& q, const EulerAngleTrig& trig,
                       Vector6d* leg_length_m, Matrix6d* dlength_dq) {
  const Matrix3d R = RotationFromEuler(trig);
  const Matrix3d E = EulerRateMatrix(trig);
  using LegVectors = Eigen::Array<double, 3, kNumLegs, Eigen::RowMajor>;
  using LegScalars = Eigen::Array<double, 1, kNumLegs>;
  const LegVectors p = R.lazyProduct(params.platform_joints_in_P_m).array();
  const LegVectors l = (p.colwise() + q.head<3>().array()) - params.base_joints_in_B_m.array();
  const LegScalars length = l.square().colwise().sum().sqrt();
  const LegVectors n = l.rowwise() / length;
  LegVectors u;  // p x n
  u.row(0) = p.row(1) * n.row(2) - p.row(2) * n.row(1);
  u.row(1) = p.row(2) * n.row(0) - p.row(0) * n.row(2);
  u.row(2) = p.row(0) * n.row(1) - p.row(1) * n.row(0);
  *leg_length_m = length.transpose();
  // J_l = [n^T, (p x n)^T E] per row.
  dlength_dq->leftCols<3>() = n.matrix().transpose();
  dlength_dq->rightCols<3>().noalias() = u.matrix().transpose() * E;
}

void PredictLegLengths(const PlatformParams& params, const EkfVector& x, Vector6d* leg_length_m,
                       MeasurementJacobian<6>* jacobian) {
  Matrix6d j;
  const Vector6d q = x.segment<6>(kEkfQ);
  PredictLegLengths(params, q, EulerAngleTrig(q.tail<3>()), leg_length_m, &j);
  jacobian->setZero();
  jacobian->block<6, 6>(0, kEkfQ) = j;
}

// h = E_b(r) rd + b_g: d/drd = E_b, d/db_g = I, d/dr = [X_phi rd, X_theta rd, 0].
void PredictGyro(const EulerAngleTrig& trig, const Vector6d& qd, const Vector3d& bias,
                 Vector3d* gyro_radps, Matrix3d* dgyro_dangles, Matrix3d* dgyro_drates) {
  const BodyRateMatrix eb(trig);
  const Vector3d rd = qd.tail<3>();
  *gyro_radps = eb.Times(rd) + bias;
  dgyro_dangles->col(0) = eb.DPhiTimes(rd);
  dgyro_dangles->col(1) = eb.DThetaTimes(rd);
  dgyro_dangles->col(2).setZero();
  *dgyro_drates = eb.Matrix();
}

void PredictGyro(const EkfVector& x, Vector3d* gyro_radps, MeasurementJacobian<3>* jacobian) {
  Matrix3d d_angles, d_rates;
  PredictGyro(EulerAngleTrig(x.segment<3>(kEkfQ + 3)), Vector6d(x.segment<6>(kEkfQd)),
              x.segment<3>(kEkfGyroBias), gyro_radps, &d_angles, &d_rates);
  jacobian->setZero();
  jacobian->block<3, 3>(0, kEkfQ + 3) = d_angles;
  jacobian->block<3, 3>(0, kEkfQd + 3) = d_rates;
  jacobian->block<3, 3>(0, kEkfGyroBias).setIdentity();
}

// In {P} (imu.h's equation rotated by R^T; r = the IMU offset in {P}):
//   f = R^T (a_t + g e_z) + alpha x r + omega x (omega x r),
//   omega = E_b rd,  alpha = E_b rdd + (X_phi phid + X_theta thetad) rd.
// d(R^T v)/dr = [R^T v]x E_b; d(omega x (omega x r))/d omega =
// (omega.r) I + omega r^T - 2 r omega^T; alpha x r = -[r]x alpha.
void PredictAccel(const EulerAngleTrig& trig, const Vector6d& qd, const Vector6d& qdd,
                  const Vector3d& imu_offset_in_P_m, double gravity_mps2, Vector3d* accel_mps2,
                  AccelJacobians* jacobians) {
  const BodyRateMatrix eb(trig);
  const Matrix3d R = RotationFromEuler(trig);
  const Vector3d& r = imu_offset_in_P_m;
  const Vector3d rd = qd.tail<3>(), rdd = qdd.tail<3>();
  const double fd = rd.x(), td = rd.y();
  const Vector3d omega = eb.Times(rd);
  const Vector3d x_phi_rd = eb.DPhiTimes(rd), x_theta_rd = eb.DThetaTimes(rd);
  const Vector3d alpha = eb.Times(rdd) + fd * x_phi_rd + td * x_theta_rd;
  const Vector3d lin = R.transpose() * (qdd.head<3>() + Vector3d(0.0, 0.0, gravity_mps2));
  *accel_mps2 = lin + alpha.cross(r) + omega.cross(omega.cross(r));
  if (jacobians == nullptr) return;

  const Matrix3d e_b = eb.Matrix();
  const Matrix3d skew_r = Skew(r);
  const Matrix3d d_centripetal =
      omega.dot(r) * Matrix3d::Identity() + omega * r.transpose() - 2.0 * r * omega.transpose();
  Matrix3d domega_dr;
  domega_dr << x_phi_rd, x_theta_rd, Vector3d::Zero();
  // d alpha / dr: X_a rdd + (X_a,phi phid + X_a,theta thetad) rd.
  Matrix3d dalpha_dr;
  dalpha_dr.col(0) = eb.DPhiTimes(rdd) + fd * eb.DPhiPhiTimes(rd) + td * eb.DPhiThetaTimes(rd);
  dalpha_dr.col(1) =
      eb.DThetaTimes(rdd) + fd * eb.DPhiThetaTimes(rd) + td * eb.DThetaThetaTimes(rd);
  dalpha_dr.col(2).setZero();
  // d alpha / drd = Edot_b + [X_phi rd, X_theta rd, 0], Edot_b = phid X_phi + thetad X_theta.
  Matrix3d dalpha_drd = fd * eb.DPhi() + td * eb.DTheta();
  dalpha_drd.col(0) += x_phi_rd;
  dalpha_drd.col(1) += x_theta_rd;
  jacobians->d_angles = Skew(lin) * e_b - skew_r * dalpha_dr + d_centripetal * domega_dr;
  jacobians->d_rates = -skew_r * dalpha_drd + d_centripetal * e_b;
  jacobians->d_qdd.leftCols<3>() = R.transpose();
  jacobians->d_qdd.rightCols<3>() = -skew_r * e_b;
}

void PredictAccel(const EkfVector& x, const Vector6d& qdd, const Vector3d& imu_offset_in_P_m,
                  double gravity_mps2, Vector3d* accel_mps2, MeasurementJacobian<3>* jacobian) {
  AccelJacobians j;
  PredictAccel(EulerAngleTrig(x.segment<3>(kEkfQ + 3)), Vector6d(x.segment<6>(kEkfQd)), qdd,
               imu_offset_in_P_m, gravity_mps2, accel_mps2, &j);
  jacobian->setZero();
  jacobian->block<3, 3>(0, kEkfQ + 3) = j.d_angles;
  jacobian->block<3, 3>(0, kEkfQd + 3) = j.d_rates;
}

Eigen::Matrix<double, 3, 6> AccelQddJacobian(const EkfVector& x, const Vector6d& qdd,
                                             const Vector3d& imu_offset_in_P_m,
                                             double gravity_mps2) {
  Vector3d unused;
  AccelJacobians j;
  PredictAccel(EulerAngleTrig(x.segment<3>(kEkfQ + 3)), Vector6d(x.segment<6>(kEkfQd)), qdd,
               imu_offset_in_P_m, gravity_mps2, &unused, &j);
  return j.d_qdd;
}

double WrapAngle(double angle_rad) { return std::remainder(angle_rad, 2.0 * M_PI); }

}  // namespace stewart
