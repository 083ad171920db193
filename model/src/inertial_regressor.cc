#include "stewart/model/inertial_regressor.h"

#include "stewart/model/dynamics.h"
#include "stewart/model/rotation.h"

namespace stewart {
namespace {

// Columns of pi: mass, first moments h = m c, inertia about the origin.
constexpr int kMass = 0;
constexpr int kFirstMoment = 1;
constexpr int kInertia = 4;

using Matrix36 = Eigen::Matrix<double, 3, 6>;
using Matrix310 = Eigen::Matrix<double, 3, kNumInertialParameters>;

// I w = InertiaTimes(w) [Ixx, Ixy, Ixz, Iyy, Iyz, Izz] for a symmetric I.
Matrix36 InertiaTimes(const Vector3d& w) {
  Matrix36 L;
  L << w.x(), w.y(), w.z(), 0.0, 0.0, 0.0,  //
      0.0, w.x(), 0.0, w.y(), w.z(), 0.0,   //
      0.0, 0.0, w.x(), 0.0, w.y(), w.z();
  return L;
}

Matrix3d TensorOf(const InertialParameters& pi) {
  const auto I = pi.segment<6>(kInertia);
  Matrix3d T;
  T << I(0), I(1), I(2), I(1), I(3), I(4), I(2), I(4), I(5);
  return T;
}

// Inertia of a point mass at r about the origin (parallel-axis term).
Matrix3d PointInertia(double mass_kg, const Vector3d& r) {
  return mass_kg * (r.squaredNorm() * Matrix3d::Identity() - r * r.transpose());
}

// The motion of the platform at one state: {P}'s rotation, the Euler rate
// matrix, the angular velocity (in {B} and in {P}).
struct BodyMotion {
  BodyMotion(const Vector6d& q, const Vector6d& qd)
      : trig(Vector3d(q.tail<3>())),
        R(RotationFromEuler(trig)),
        E(EulerRateMatrix(trig)),
        omega(E * qd.tail<3>()),
        omega_in_P(R.transpose() * omega) {}
  EulerAngleTrig trig;
  Matrix3d R;
  Matrix3d E;
  Vector3d omega;
  Vector3d omega_in_P;
};

// Regressors of the body's linear momentum P = m v + omega x (R h) and of its
// angular momentum about {P}'s origin H = (R h) x v + R I_O omega_P, both {B}.
Matrix310 LinearMomentumRegressor(const BodyMotion& b, const Vector3d& v) {
  Matrix310 Y = Matrix310::Zero();
  Y.col(kMass) = v;
  Y.block<3, 3>(0, kFirstMoment) = Skew(b.omega) * b.R;
  return Y;
}
Matrix310 AngularMomentumRegressor(const BodyMotion& b, const Vector3d& v) {
  Matrix310 Y = Matrix310::Zero();
  Y.block<3, 3>(0, kFirstMoment) = -Skew(v) * b.R;
  Y.block<3, 6>(0, kInertia) = b.R * InertiaTimes(b.omega_in_P);
  return Y;
}

// Generalised forces of a wrench about {P}'s origin: [f; E^T tau].
InertialRegressor Generalised(const Matrix3d& E, const Matrix310& force, const Matrix310& torque) {
  InertialRegressor Y;
  Y.topRows<3>() = force;
  Y.bottomRows<3>().noalias() = E.transpose() * torque;
  return Y;
}

PlatformParams WithMasslessPlatform(const PlatformParams& params) {
  PlatformParams legs_only = params;
  legs_only.platform_mass_kg = 0.0;
  legs_only.platform_com_in_P_m.setZero();
  legs_only.platform_inertia_kgm2.setZero();
  legs_only.platform_inertia_products_kgm2.setZero();
  return legs_only;
}

}  // namespace

InertialParameters InertialParametersOf(const PlatformParams& params) {
  const double m = params.platform_mass_kg;
  const Vector3d& c = params.platform_com_in_P_m;
  const Matrix3d I_O = PlatformInertiaInP(params) + PointInertia(m, c);
  InertialParameters pi;
  pi << m, m * c, I_O(0, 0), I_O(0, 1), I_O(0, 2), I_O(1, 1), I_O(1, 2), I_O(2, 2);
  return pi;
}

PlatformBody PlatformBodyOf(const InertialParameters& pi) {
  PlatformBody body;
  body.mass_kg = pi(kMass);
  body.com_in_P_m = pi.segment<3>(kFirstMoment) / body.mass_kg;
  body.inertia_about_com_in_P_kgm2 = TensorOf(pi) - PointInertia(body.mass_kg, body.com_in_P_m);
  return body;
}

PlatformParams WithPlatformBody(const PlatformParams& params, const PlatformBody& body) {
  PlatformParams out = params;
  const Matrix3d& I = body.inertia_about_com_in_P_kgm2;
  out.platform_mass_kg = body.mass_kg;
  out.platform_com_in_P_m = body.com_in_P_m;
  out.platform_inertia_kgm2 = I.diagonal();
  out.platform_inertia_products_kgm2 = Vector3d(I(0, 1), I(0, 2), I(1, 2));
  return out;
}

// Newton-Euler about {P}'s origin O (a point of the body), in {B}:
//   f   = m (a_O + g e_z) + (alpha x + omega x omega x) R h
//   tau = (R h) x (a_O + g e_z) + R (I_O alpha_P + omega_P x I_O omega_P)
// and the generalised force is [f; E^T tau] (virtual power, omega = E rd).
InertialRegressor PlatformInertialRegressor(double gravity_mps2, const Vector6d& q,
                                            const Vector6d& qd, const Vector6d& qdd) {
  const BodyMotion b(q, qd);
  const Vector3d alpha =
      b.E * qdd.tail<3>() + EulerRateBiasAcceleration(b.trig, Vector3d(qd.tail<3>()));
  const Vector3d alpha_in_P = b.R.transpose() * alpha;
  const Vector3d a_g = qdd.head<3>() + Vector3d(0.0, 0.0, gravity_mps2);
  const Matrix3d W = Skew(b.omega);

  Matrix310 force = Matrix310::Zero();
  force.col(kMass) = a_g;
  force.block<3, 3>(0, kFirstMoment) = (Skew(alpha) + W * W) * b.R;
  Matrix310 torque = Matrix310::Zero();
  torque.block<3, 3>(0, kFirstMoment) = -Skew(a_g) * b.R;
  torque.block<3, 6>(0, kInertia) =
      b.R * (InertiaTimes(alpha_in_P) + Skew(b.omega_in_P) * InertiaTimes(b.omega_in_P));
  return Generalised(b.E, force, torque);
}

// p = J^T [P; H] with J = diag(I, E) the map from qd to (v_O, omega).
InertialRegressor MomentumRegressor(const Vector6d& q, const Vector6d& qd) {
  const BodyMotion b(q, qd);
  const Vector3d v = qd.head<3>();
  return Generalised(b.E, LinearMomentumRegressor(b, v), AngularMomentumRegressor(b, v));
}

// Newton-Euler in momentum form about the moving point O:
//   f = dP/dt + m g e_z,   tau = dH/dt + v x P + (R h) x g e_z,
// so J^T [f; tau] - d/dt (J^T [P; H]) = J^T [m g e_z; v x P + (R h) x g e_z] - Jdot^T [P; H],
// with Jdot = diag(0, Edot).
InertialRegressor MomentumRemainderRegressor(double gravity_mps2, const Vector6d& q,
                                             const Vector6d& qd) {
  const BodyMotion b(q, qd);
  const Vector3d v = qd.head<3>();
  const Vector3d g_up(0.0, 0.0, gravity_mps2);
  const Matrix3d Ed = EulerRateMatrixDerivative(b.trig, Vector3d(qd.tail<3>()));

  Matrix310 force = Matrix310::Zero();
  force.col(kMass) = g_up;
  Matrix310 torque = Skew(v) * LinearMomentumRegressor(b, v);
  torque.block<3, 3>(0, kFirstMoment) -= Skew(g_up) * b.R;
  InertialRegressor Y = Generalised(b.E, force, torque);
  Y.bottomRows<3>().noalias() -= Ed.transpose() * AngularMomentumRegressor(b, v);
  return Y;
}

LegMomentumTerms LegMomentum(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                             double step_s) {
  const PlatformParams legs = WithMasslessPlatform(params);
  const DynamicsTerms now = EvaluateDynamics(legs, q, qd);
  const Vector6d dq = step_s * qd;
  const Matrix6d M_ahead = EvaluateDynamics(legs, q + dq, qd).M;
  const Matrix6d M_behind = EvaluateDynamics(legs, q - dq, qd).M;
  const Vector6d Mdot_qd = (M_ahead - M_behind) * qd / (2.0 * step_s);
  return {now.M * qd, now.C_qd + now.G - Mdot_qd};
}

Vector6d LegDynamicsForce(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                          const Vector6d& qdd) {
  const DynamicsTerms legs = EvaluateDynamics(WithMasslessPlatform(params), q, qd);
  return legs.M * qdd + legs.C_qd + legs.G;
}

}  // namespace stewart
