#include "stewart/model/dynamics.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "stewart/model/rotation.h"

namespace stewart {
namespace {

// Each leg is reduced to two point-like terms at its platform joint a_i:
//  - cylinder translation and both transverse rotations, 1/2 mu |nd|^2 with
//    mu = m1 e1^2 + I1 + I2: the kinetic energy of a point of mass mu at the
//    unit vector n_i;
//  - rod translation, 1/2 m2 |d/dt (a_i - e2 n_i)|^2.
// With v = J_a qd the joint velocity and J_a = [I, -[R p_i]x E], every term is
// accumulated as a 3x3 "joint-space" inertia A_i and joint-space forces, then
// mapped through J_a^T (see docs/model.md).
struct JointSpaceTerms {
  Matrix3d A;       // joint-space inertia (kg)
  Vector3d f_bias;  // A-weighted bias acceleration (N)
  Vector3d f_grav;  // gravity (N)
};

JointSpaceTerms LegJointTerms(const LegParams& leg, double g, const Vector3d& n, double length,
                              const Vector3d& v, const Vector3d& a_bias) {
  const double mu =
      leg.cylinder_mass_kg * leg.cylinder_com_from_base_m * leg.cylinder_com_from_base_m +
      leg.cylinder_inertia_kgm2 + leg.rod_inertia_kgm2;
  const double m2 = leg.rod_mass_kg;
  const double inv_l = 1.0 / length;
  const double s = 1.0 - leg.rod_com_from_platform_m * inv_l;  // P2 = nn^T + s P_perp

  const Matrix3d nnT = n * n.transpose();
  const Matrix3d P_perp = Matrix3d::Identity() - nnT;

  const double ld = n.dot(v);
  const Vector3d nd = (v - n * ld) * inv_l;
  // ndd with qdd = 0: [P_perp a - 2 Ld nd - n L |nd|^2] / L
  const Vector3d P_perp_a = a_bias - n * n.dot(a_bias);
  const Vector3d ndd = (P_perp_a - 2.0 * ld * nd) * inv_l - n * nd.squaredNorm();

  JointSpaceTerms out;
  out.A = m2 * nnT + (mu * inv_l * inv_l + m2 * s * s) * P_perp;
  // mu J_n^T ndd  with J_n = P_perp J_a / L
  const Vector3d f_mu = (mu * inv_l) * (ndd - n * n.dot(ndd));
  // m2 J_r^T r_dd  with r = a - e2 n, J_r = P2 J_a
  const Vector3d rdd = a_bias - leg.rod_com_from_platform_m * ndd;
  const Vector3d f_rod = m2 * (n * n.dot(rdd) + s * (rdd - n * n.dot(rdd)));
  out.f_bias = f_mu + f_rod;
  // V = g (m1 e1 n_z + m2 (a - e2 n)_z)
  const Vector3d ez = Vector3d::UnitZ();
  const Vector3d P_perp_ez = ez - n * n.z();
  out.f_grav = g * (leg.cylinder_mass_kg * leg.cylinder_com_from_base_m * inv_l * P_perp_ez +
                    m2 * (n * n.z() + s * P_perp_ez));
  return out;
}

}  // namespace

void EvaluateDynamics(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                      DynamicsTerms* terms) {
  const Vector3d t = q.head<3>();
  const Vector3d rpy = q.tail<3>();
  const Vector3d td = qd.head<3>();
  const Vector3d rpyd = qd.tail<3>();
  const Matrix3d R = RotationFromEuler(rpy);
  const Matrix3d E = EulerRateMatrix(rpy);
  const Vector3d omega = E * rpyd;
  const Vector3d omegad_bias = EulerRateBiasAcceleration(rpy, rpyd);
  const double g = params.gravity_mps2;

  // Accumulators in (translation, angular velocity) coordinates; E is applied
  // once at the end: for a point at offset p, J = [I, -[p]x E].
  Matrix3d M_tt = Matrix3d::Zero();
  Matrix3d N = Matrix3d::Zero();                              // sum A [p]x       -> M_tr = -N E
  Matrix3d K = Matrix3d::Zero();                              // sum [p]x^T A [p]x -> M_rr = E^T K E
  Vector3d f_t = Vector3d::Zero(), tau = Vector3d::Zero();    // bias
  Vector3d g_t = Vector3d::Zero(), g_tau = Vector3d::Zero();  // gravity

  auto accumulate_point = [&](const Vector3d& p, const Matrix3d& A, const Vector3d& f_bias,
                              const Vector3d& f_grav) {
    const Matrix3d S = Skew(p);
    const Matrix3d AS = A * S;
    M_tt += A;
    N += AS;
    K -= S * AS;  // S^T = -S
    f_t += f_bias;
    tau += p.cross(f_bias);
    g_t += f_grav;
    g_tau += p.cross(f_grav);
  };

  // Platform: mass at its CoM, plus rotational inertia.
  {
    const Vector3d c = R * params.platform_com_m;
    const double m = params.platform_mass_kg;
    const Vector3d a_bias = omegad_bias.cross(c) + omega.cross(omega.cross(c));
    accumulate_point(c, m * Matrix3d::Identity(), m * a_bias, Vector3d(0.0, 0.0, m * g));
    const Matrix3d I_world = R * params.platform_inertia_kgm2.asDiagonal() * R.transpose();
    K += I_world;
    tau += I_world * omegad_bias + omega.cross(I_world * omega);
  }

  // Legs.
  for (int i = 0; i < kNumLegs; ++i) {
    const Vector3d p = R * params.platform_joints_m.col(i);
    const Vector3d leg = t + p - params.base_joints_m.col(i);
    const double length = leg.norm();
    const Vector3d n = leg / length;
    terms->leg_length_m(i) = length;
    terms->H.block<3, 1>(0, i) = n;
    terms->H.block<3, 1>(3, i) = E.transpose() * p.cross(n);
    const Vector3d v = td + omega.cross(p);
    const Vector3d a_bias = omegad_bias.cross(p) + omega.cross(omega.cross(p));
    const JointSpaceTerms leg_terms = LegJointTerms(params.leg, g, n, length, v, a_bias);
    accumulate_point(p, leg_terms.A, leg_terms.f_bias, leg_terms.f_grav);
  }

  const Matrix3d M_tr = -N * E;
  terms->M.topLeftCorner<3, 3>() = M_tt;
  terms->M.topRightCorner<3, 3>() = M_tr;
  terms->M.bottomLeftCorner<3, 3>() = M_tr.transpose();
  terms->M.bottomRightCorner<3, 3>() = E.transpose() * K * E;
  terms->C_qd.head<3>() = f_t;
  terms->C_qd.tail<3>() = E.transpose() * tau;
  terms->G.head<3>() = g_t;
  terms->G.tail<3>() = E.transpose() * g_tau;
}

DynamicsTerms EvaluateDynamics(const PlatformParams& params, const Vector6d& q,
                               const Vector6d& qd) {
  DynamicsTerms terms;
  EvaluateDynamics(params, q, qd, &terms);
  return terms;
}

Vector6d ForwardDynamics(const DynamicsTerms& terms, const Vector6d& force_n) {
  return terms.M.llt().solve(terms.H * force_n - terms.C_qd - terms.G);
}

Vector6d InverseDynamics(const DynamicsTerms& terms, const Vector6d& qdd) {
  return terms.H.partialPivLu().solve(terms.M * qdd + terms.C_qd + terms.G);
}

double KineticEnergy(const DynamicsTerms& terms, const Vector6d& qd) {
  return 0.5 * qd.dot(terms.M * qd);
}

double PotentialEnergy(const PlatformParams& params, const Vector6d& q) {
  const LegGeometry legs = ComputeLegGeometry(params, q);
  const Matrix3d R = RotationFromEuler(q.tail<3>());
  const double g = params.gravity_mps2;
  double v = g * params.platform_mass_kg * (q(2) + (R * params.platform_com_m).z());
  const LegParams& leg = params.leg;
  for (int i = 0; i < kNumLegs; ++i) {
    const double n_z = legs.unit_m(2, i);
    const double a_z = q(2) + legs.platform_offset_m(2, i);
    const double b_z = params.base_joints_m(2, i);
    v += g * leg.cylinder_mass_kg * (b_z + leg.cylinder_com_from_base_m * n_z);
    v += g * leg.rod_mass_kg * (a_z - leg.rod_com_from_platform_m * n_z);
  }
  return v;
}

}  // namespace stewart
