#include "stewart/model/dynamics.h"

#include <cmath>

#include "leg_arrays.h"
#include "stewart/model/linear_algebra6.h"
#include "stewart/model/rotation.h"

namespace stewart {
namespace {

using internal::Cross;
using internal::Dot;
using internal::LegScalars;
using internal::LegVectors;
using internal::SumOfOuterProducts;

// Each leg is reduced to two point-like terms at its platform joint a_i:
//  - cylinder translation and both transverse rotations, 1/2 mu |nd|^2 with
//    mu = m1 e1^2 + I1 + I2: the kinetic energy of a point of mass mu at the
//    unit vector n_i;
//  - rod translation, 1/2 m2 |d/dt (a_i - e2 n_i)|^2;
//  - the actuator's rotor, 1/2 m_r Ld^2 with Ld = n . v (reflected mass).
// With v = J_a qd the joint velocity and J_a = [I, -[p]x E] (p = R p_i, {B}),
// both give a 3x3 "joint-space" inertia at a_i (kg),
//   A = (m2 + m_r) n n^T + c (I - n n^T) = c I + d n n^T,
//   c = mu / L^2 + m2 s^2,  d = m2 + m_r - c,  s = 1 - e2 / L,
// and joint-space bias and gravity forces (N), mapped through J_a^T
// (docs/model.md, "Dynamics"). A is rank one in n, so no 3x3 product is needed.
struct LegJointTerms {
  LegScalars c;               // isotropic part of A (kg)
  LegScalars d;               // n n^T part of A (kg)
  LegVectors f_bias;          // joint-space bias force (N)
  LegVectors f_grav;          // joint-space gravity force (N)
  LegScalars leg_bias_accel;  // Ldd at qdd = 0: n . a_bias + L |nd|^2 (m/s^2)
};

// The leg's mass constants, the same for every leg.
struct LegMassConstants {
  explicit LegMassConstants(const LegParams& leg)
      : mu(leg.cylinder_mass_kg * leg.cylinder_com_from_base_m * leg.cylinder_com_from_base_m +
           leg.cylinder_inertia_kgm2 + leg.rod_inertia_kgm2),
        m2(leg.rod_mass_kg),
        e2(leg.rod_com_from_platform_m),
        m1_e1(leg.cylinder_mass_kg * leg.cylinder_com_from_base_m),
        m_r(leg.actuator_reflected_mass_kg) {}
  double mu;     // kg m^2
  double m2;     // kg
  double e2;     // m
  double m1_e1;  // kg m
  double m_r;    // kg
};

// n: unit leg vectors, inv_l = 1/L (1/m), v and a_bias: velocity (m/s) and
// bias acceleration (m/s^2, the part with qdd = 0) of the platform joints,
// all in {B}.
LegJointTerms ComputeLegJointTerms(const LegMassConstants& k, double g, const LegVectors& n,
                                   const LegScalars& inv_l, const LegVectors& v,
                                   const LegVectors& a_bias) {
  // Rod CoM Jacobian: J_r = (n n^T + s (I - n n^T)) J_a.
  const LegScalars s = 1.0 - k.e2 * inv_l;
  LegJointTerms out;
  out.c = k.mu * inv_l.square() + k.m2 * s.square();
  out.d = k.m2 + k.m_r - out.c;
  const LegScalars ld = Dot(n, v);                                 // leg speed (m/s)
  const LegVectors nd = (v - n.rowwise() * ld).rowwise() * inv_l;  // (I - n n^T) v / L (1/s)
  // With ndd|qdd=0 = [(I - n n^T) a_bias - 2 Ld nd] / L - n |nd|^2 the two
  // terms mu J_n^T ndd + m2 J_r^T (a_bias - e2 ndd) collect into
  //   f_bias = A a_bias + m2 e2 |nd|^2 n + 2 Ld (m2 s e2 / L - mu / L^2) nd.
  // The rotor adds m_r Ldd|qdd=0 n = m_r (n . a_bias + L |nd|^2) n (its
  // Lagrangian term is m_r Ldd J_l^T: the velocity terms cancel), whose first
  // part is in A a_bias.
  const LegScalars nd_sq = nd.square().colwise().sum();
  const LegScalars along_n = out.d * Dot(n, a_bias) + (k.m2 * k.e2 + k.m_r / inv_l) * nd_sq;
  // Apart from along_n, whose expression (and so its rounding) stays as it was.
  out.leg_bias_accel = Dot(n, a_bias) + nd_sq / inv_l;
  const LegScalars along_nd = 2.0 * ld * inv_l * (k.m2 * k.e2 * s - k.mu * inv_l);
  out.f_bias = a_bias.rowwise() * out.c + n.rowwise() * along_n + nd.rowwise() * along_nd;
  // V = g (m1 e1 n_z + m2 (a - e2 n)_z):
  //   f_grav = g [c_g e_z + (m2 - c_g) n_z n],  c_g = m1 e1 / L + m2 s.
  const LegScalars c_g = k.m1_e1 * inv_l + k.m2 * s;
  out.f_grav = n.rowwise() * (g * (k.m2 - c_g) * n.row(2));
  out.f_grav.row(2) += g * c_g;
  return out;
}

}  // namespace

// Sums over the point terms, in (translation, angular velocity) coordinates;
// E is applied once at the end. For a point at offset p ({B}) with
// joint-space inertia A = c I + d n n^T and u = p x n:
//   M_tt += A
//   N    += A [p]x         = c [p]x - d n u^T                 (M_tr = -N E)
//   K    += [p]x^T A [p]x  = c (|p|^2 I - p p^T) + d u u^T    (M_rr = E^T K E)
//   f_t  += f,  tau += p x f   (bias forces; likewise gravity)
// The platform adds its CoM as such a point (A = m I) and its rotational
// inertia R I_p R^T to K.
void EvaluateDynamics(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                      DynamicsTerms* terms) {
  const Vector3d t = q.head<3>();
  const Vector3d td = qd.head<3>();
  const Vector3d rpyd = qd.tail<3>();
  const EulerAngleTrig trig(q.tail<3>());
  const Matrix3d R = RotationFromEuler(trig);
  const Matrix3d E = EulerRateMatrix(trig);
  const Vector3d omega = E * rpyd;
  const Vector3d omegad_bias = EulerRateBiasAcceleration(trig, rpyd);
  const double g = params.gravity_mps2;

  // Legs: geometry (p = R p_i, n, L, u = p x n), joint velocity and bias
  // acceleration, then the joint-space terms.
  const internal::LegArrays geometry = internal::ComputeLegArrays(params, R, t);
  const LegVectors& p = geometry.offset;
  const LegScalars& inv_l = geometry.inverse_length;
  const LegVectors& n = geometry.unit;
  const LegVectors u = Cross(p, n);
  const LegVectors w = Cross(omega, p);  // omega x p
  const LegVectors v = w.colwise() + td.array();
  const LegVectors a_bias = Cross(omegad_bias, p) + Cross(omega, w);
  const LegJointTerms legs =
      ComputeLegJointTerms(LegMassConstants(params.leg), g, n, inv_l, v, a_bias);
  terms->leg_length_m = geometry.length.transpose();
  terms->leg_bias_accel_mps2 = legs.leg_bias_accel.transpose();
  terms->H.topRows<3>() = n.matrix();
  terms->H.bottomRows<3>().noalias() = E.transpose() * u.matrix();

  // Platform CoM and inertia.
  const Vector3d c = R * params.platform_com_in_P_m;
  const double m = params.platform_mass_kg;
  const Vector3d w_c = omega.cross(c);
  const Vector3d f_c = m * (omegad_bias.cross(c) + omega.cross(w_c));  // m a_bias at the CoM
  const Vector3d g_c(0.0, 0.0, m * g);
  const Matrix3d I_world = R * PlatformInertiaInP(params) * R.transpose();

  const LegVectors cp = p.rowwise() * legs.c;
  const LegVectors dn = n.rowwise() * legs.d;
  const LegVectors du = u.rowwise() * legs.d;
  const double sum_c = m + legs.c.sum();
  const Vector3d sum_cp = m * c + cp.matrix().rowwise().sum();
  const double sum_c_pp = m * c.squaredNorm() + Dot(cp, p).sum();

  Matrix3d M_tt = SumOfOuterProducts(dn, n);
  M_tt.diagonal().array() += sum_c;
  const Matrix3d N = Skew(sum_cp) - SumOfOuterProducts(dn, u);
  Matrix3d K =
      SumOfOuterProducts(du, u) - SumOfOuterProducts(cp, p) - m * c * c.transpose() + I_world;
  K.diagonal().array() += sum_c_pp;

  Matrix6d& M = terms->M;
  M.topLeftCorner<3, 3>() = M_tt;
  M.bottomLeftCorner<3, 3>().noalias() = -E.transpose() * N.transpose();  // M_tr^T
  M.bottomRightCorner<3, 3>().noalias() = E.transpose() * (K * E);
  // M is symmetric by construction; copying the lower triangle makes it so to
  // the last bit (the sums round differently above and below the diagonal).
  for (int j = 1; j < 6; ++j) {
    for (int i = 0; i < j; ++i) M(i, j) = M(j, i);
  }

  const Vector3d f_t = f_c + legs.f_bias.matrix().rowwise().sum();
  const Vector3d tau = c.cross(f_c) + Cross(p, legs.f_bias).matrix().rowwise().sum() +
                       I_world * omegad_bias + omega.cross(I_world * omega);
  const Vector3d g_t = g_c + legs.f_grav.matrix().rowwise().sum();
  const Vector3d g_tau = c.cross(g_c) + Cross(p, legs.f_grav).matrix().rowwise().sum();
  terms->C_qd.head<3>() = f_t;
  terms->C_qd.tail<3>().noalias() = E.transpose() * tau;
  terms->G.head<3>() = g_t;
  terms->G.tail<3>().noalias() = E.transpose() * g_tau;
}

DynamicsTerms EvaluateDynamics(const PlatformParams& params, const Vector6d& q,
                               const Vector6d& qd) {
  DynamicsTerms terms;
  EvaluateDynamics(params, q, qd, &terms);
  return terms;
}

Vector6d ForwardDynamics(const DynamicsTerms& terms, const Vector6d& force_n) {
  return ForwardDynamics(terms, force_n, Vector6d::Zero());
}

Vector6d ForwardDynamics(const DynamicsTerms& terms, const Vector6d& force_n,
                         const Vector6d& external_generalised_force) {
  Cholesky6 inertia;
  if (!inertia.Compute(terms.M)) return Vector6d::Constant(NAN);
  return inertia.Solve<1>(terms.H * force_n + external_generalised_force - terms.C_qd - terms.G);
}

Vector6d GeneralisedForceOfWrench(const Vector6d& q, const Vector6d& wrench_in_B) {
  Vector6d out;
  out.head<3>() = wrench_in_B.head<3>();
  out.tail<3>().noalias() =
      EulerRateMatrix(Vector3d(q.tail<3>())).transpose() * wrench_in_B.tail<3>();
  return out;
}

Vector6d InverseDynamics(const DynamicsTerms& terms, const Vector6d& qdd) {
  return InverseDynamics(terms, qdd, Vector6d::Zero());
}

Vector6d InverseDynamics(const DynamicsTerms& terms, const Vector6d& qdd,
                         const Vector6d& external_generalised_force) {
  Vector6d force_n = terms.M * qdd + terms.C_qd + terms.G - external_generalised_force;
  if (!SolvePartialPivot6(terms.H, &force_n)) return Vector6d::Constant(NAN);
  return force_n;
}

double KineticEnergy(const DynamicsTerms& terms, const Vector6d& qd) {
  return 0.5 * qd.dot(terms.M * qd);
}

double PotentialEnergy(const PlatformParams& params, const Vector6d& q) {
  const LegGeometry legs = ComputeLegGeometry(params, q);
  const Matrix3d R = RotationFromEuler(q.tail<3>());
  const double g = params.gravity_mps2;
  double v = g * params.platform_mass_kg * (q(2) + (R * params.platform_com_in_P_m).z());
  const LegParams& leg = params.leg;
  for (int i = 0; i < kNumLegs; ++i) {
    const double n_z = legs.unit_in_B(2, i);
    const double a_z = q(2) + legs.platform_offset_in_B_m(2, i);
    const double b_z = params.base_joints_in_B_m(2, i);
    v += g * leg.cylinder_mass_kg * (b_z + leg.cylinder_com_from_base_m * n_z);
    v += g * leg.rod_mass_kg * (a_z - leg.rod_com_from_platform_m * n_z);
  }
  return v;
}

}  // namespace stewart
