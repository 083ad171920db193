#include "stewart/estimator/process_model.h"

#include "stewart/model/dynamics.h"
#include "stewart/model/linear_algebra6.h"
#include "stewart/model/rotation.h"
#include "stewart/model/shared_dynamics_terms.h"

namespace stewart {
namespace {

// The six legs side by side: row k holds component k of one vector per leg.
using LegScalars = Eigen::Array<double, 1, kNumLegs>;
using LegVectors = Eigen::Array<double, 3, kNumLegs, Eigen::RowMajor>;

LegVectors Cross(const LegVectors& a, const LegVectors& b) {
  LegVectors c;
  c.row(0) = a.row(1) * b.row(2) - a.row(2) * b.row(1);
  c.row(1) = a.row(2) * b.row(0) - a.row(0) * b.row(2);
  c.row(2) = a.row(0) * b.row(1) - a.row(1) * b.row(0);
  return c;
}

// a_i x b with the same b for every leg.
LegVectors CrossWith(const LegVectors& a, const Vector3d& b) {
  LegVectors c;
  c.row(0) = a.row(1) * b.z() - a.row(2) * b.y();
  c.row(1) = a.row(2) * b.x() - a.row(0) * b.z();
  c.row(2) = a.row(0) * b.y() - a.row(1) * b.x();
  return c;
}

// sum_i a_i b_i^T (3x3).
Matrix3d SumOfOuterProducts(const LegVectors& a, const LegVectors& b) {
  return a.matrix().lazyProduct(b.matrix().transpose());
}

}  // namespace

Vector6d DynamicsAcceleration(const PlatformParams& params, double friction_nspm, const Vector6d& q,
                              const Vector6d& qd, const Vector6d& force_n) {
  DynamicsTerms terms;
  EvaluateDynamics(params, q, qd, &terms);
  return ForwardDynamics(terms, force_n - friction_nspm * (terms.H.transpose() * qd));
}

// The force and gravity part of qdd is the gradient of one scalar function,
//   Phi(q) = sum_i F_i L_i(q) - V(q)      (H F - G = dPhi/dq, F held),
// and every term of it is a function of one leg vector l_i = t + R p_i - b_i
// (or of the platform's CoM): phi_i(l) = F_i |l| - g k l_z / |l| - g m2 l_z,
// k = m1 e1 - m2 e2 (the leg's potential, as G in dynamics.cc). So
//   d2Phi/dq2 = sum_i J_i^T Phi_i J_i + (second derivatives of R, contracted),
// J_i = dl_i/dq = [I, -[p_i]x E], Phi_i = d2phi_i/dl2 = a I + b n n^T + c (n e_z^T + e_z n^T):
//   a = F/L + g k n_z/L^2,  b = -F/L - 3 g k n_z/L^2,  c = g k/L^2.
// The friction F = F_cmd - c_v ld (ld = H^T qd) adds -c_v H d(ld)/dq, with
//   d(ld_i)/dq = [nd_i^T, (p_i x (nd_i + n_i x omega))^T E + u_i^T [dE/dr rd]],
// nd = (v - n ld) / L, v = td + omega x p, u = p x n. Then
//   dqdd/dq = M^-1 (d2Phi/dq2 - c_v H d(ld)/dq)
// without the inertial part -M^-1 d(M qdd + C qd)/dq, O(|qdd| + |qd|^2):
// ~1e-4 of the rest at the scenario's speeds (docs/estimator.md).
// dqdd/dqd = -M^-1 (c_v H H^T + d(C qd)/dqd); the Coriolis part is O(|qd|)
// (C qd is quadratic in qd): ~m |qd| / L ~ 0.05 kg/s at the scenario's speeds
// against c_v |H H^T| ~ 2 N s/m for the friction, so it is left out.
void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const Vector6d& qd, const Vector6d& force_n,
                                   Vector6d* qdd, Matrix6d* dqdd_dq, Matrix6d* dqdd_dqd) {
  DynamicsAccelerationJacobians(params, friction_nspm, q, EulerAngleTrig(q.tail<3>()), qd, force_n,
                                qdd, dqdd_dq, dqdd_dqd);
}

void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const EulerAngleTrig& trig,
                                   const Vector6d& qd, const Vector6d& force_n, Vector6d* qdd,
                                   Matrix6d* dqdd_dq, Matrix6d* dqdd_dqd) {
  Matrix6d m_inv;
  DynamicsAccelerationJacobians(params, friction_nspm, q, trig, qd, force_n, Vector6d::Zero(), qdd,
                                dqdd_dq, dqdd_dqd, &m_inv);
}

void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const EulerAngleTrig& trig,
                                   const Vector6d& qd, const Vector6d& force_n,
                                   const Vector6d& disturbance_n, Vector6d* qdd, Matrix6d* dqdd_dq,
                                   Matrix6d* dqdd_dqd, Matrix6d* m_inv, SharedDynamicsTerms* shared,
                                   Matrix6d* dqdd_dforce, Matrix6d* h) {
  DynamicsTerms terms;
  EvaluateDynamics(params, shared, q, qd, &terms);
  const Matrix6d& H = terms.H;
  if (h != nullptr) *h = H;
  const Vector6d leg_speed_mps = H.transpose() * qd;
  const Vector6d force = force_n - friction_nspm * leg_speed_mps;

  const Matrix3d R = RotationFromEuler(trig);
  const Matrix3d E = EulerRateMatrix(trig);
  const Vector3d omega = E * qd.tail<3>();
  const double g = params.gravity_mps2;
  const LegParams& leg = params.leg;
  const double gk = g * (leg.cylinder_mass_kg * leg.cylinder_com_from_base_m -
                         leg.rod_mass_kg * leg.rod_com_from_platform_m);

  // Leg geometry: n and L as the model computed them, p = R p_i.
  const LegVectors n = H.topRows<3>().array();
  const LegScalars inv_l = terms.leg_length_m.transpose().array().inverse();
  const LegVectors p = R.lazyProduct(params.platform_joints_in_P_m).array();
  const LegVectors u = Cross(p, n);
  LegVectors k;  // p x e_z
  k.row(0) = p.row(1);
  k.row(1) = -p.row(0);
  k.row(2).setZero();
  const LegScalars f = force.transpose().array();
  const LegScalars nz = n.row(2);
  const LegScalars c = gk * inv_l.square();
  const LegScalars a = f * inv_l + c * nz;
  const LegScalars b = -f * inv_l - 3.0 * c * nz;

  // Hessian of Phi in (translation, rotation vector) coordinates.
  const LegVectors bn = n.rowwise() * b;
  const LegVectors cn = n.rowwise() * c;
  const LegVectors cu = u.rowwise() * c;
  const LegVectors ap = p.rowwise() * a;
  const Vector3d sum_cn = cn.matrix().rowwise().sum();
  Matrix3d h_tt = SumOfOuterProducts(bn, n);
  h_tt.diagonal().array() += a.sum();
  h_tt.col(2) += sum_cn;
  h_tt.row(2) += sum_cn.transpose();
  // sum Phi_i [p_i]x
  Matrix3d c_tr =
      Skew(ap.matrix().rowwise().sum()) - SumOfOuterProducts(bn, u) - SumOfOuterProducts(cn, k);
  c_tr.row(2) -= cu.matrix().rowwise().sum().transpose();
  // sum [p_i]x^T Phi_i [p_i]x
  const Matrix3d uk = SumOfOuterProducts(cu, k);
  Matrix3d k_rr =
      SumOfOuterProducts(u.rowwise() * b, u) - SumOfOuterProducts(ap, p) + uk + uk.transpose();
  k_rr.diagonal().array() += (ap * p).sum();

  // Second derivatives of the points R x (x = p_i and the CoM) by the
  // angles: d2(R x)/dr_a dr_b = E_b x (E_a x R x) + dE_b/dr_a x R x (E_a:
  // column a of E). Weighted by the gradients dPhi/dl_i =
  // (F + g k n_z / L) n - (g k / L + g m2) e_z at the legs and -g m e_z at the
  // CoM, and summed, they give E^T (Q^T - tr(Q) I) E + [tau . dE_b/dr_a] with
  // Q = sum x grad^T and tau = sum x cross grad.
  LegVectors grad = n.rowwise() * (f + gk * nz * inv_l);
  grad.row(2) -= gk * inv_l + g * leg.rod_mass_kg;
  const Vector3d com = R * params.platform_com_in_P_m;
  const double weight = g * params.platform_mass_kg;
  Matrix3d q_t = SumOfOuterProducts(grad, p);  // Q^T
  q_t.row(2) -= weight * com.transpose();
  const Vector3d tau =
      Cross(p, grad).matrix().rowwise().sum() - weight * Vector3d(com.y(), -com.x(), 0.0);
  k_rr += q_t;
  k_rr.diagonal().array() -= q_t.trace();
  Matrix3d rr = E.transpose() * (k_rr * E);
  {
    const double ct = trig.cos_theta, st = trig.sin_theta, cp = trig.cos_psi, sp = trig.sin_psi;
    rr(1, 0) -= tau.x() * cp * st + tau.y() * sp * st + tau.z() * ct;  // dE_0/dtheta
    rr(2, 0) += ct * (tau.y() * cp - tau.x() * sp);                    // dE_0/dpsi
    rr(2, 1) -= tau.x() * cp + tau.y() * sp;                           // dE_1/dpsi
  }

  Matrix6d numerator;
  const Matrix3d c_tr_e = c_tr * E;
  numerator.topLeftCorner<3, 3>() = h_tt;
  numerator.topRightCorner<3, 3>() = -c_tr_e;
  numerator.bottomLeftCorner<3, 3>() = -c_tr_e.transpose();
  numerator.bottomRightCorner<3, 3>() = rr;

  // Friction: -c_v H d(ld)/dq.
  const LegVectors v = CrossWith(p, -omega).colwise() + qd.head<3>().array();  // omega x p + td
  const LegScalars ld = leg_speed_mps.transpose().array();
  const LegVectors nd = (v - n.rowwise() * ld).rowwise() * inv_l;
  const LegVectors pw = Cross(p, nd + CrossWith(n, omega));
  Matrix3d dE_rd;  // column a: dE/dr_a rd
  {
    const double ct = trig.cos_theta, st = trig.sin_theta, cp = trig.cos_psi, sp = trig.sin_psi;
    const double fd = qd(3), td = qd(4);
    dE_rd << 0.0, -cp * st * fd, -sp * ct * fd - cp * td,  //
        0.0, -sp * st * fd, cp * ct * fd - sp * td,        //
        0.0, -ct * fd, 0.0;
  }
  Matrix6d dld_dq;
  dld_dq.leftCols<3>() = nd.matrix().transpose();
  dld_dq.rightCols<3>() =
      pw.matrix().transpose().lazyProduct(E) + u.matrix().transpose().lazyProduct(dE_rd);
  numerator.noalias() -= friction_nspm * H.lazyProduct(dld_dq);

  // One factor of M, one substitution for qdd, dqdd/dq and dqdd/dqd.
  Cholesky6 inertia;
  if (!inertia.Compute(terms.M)) {
    qdd->setConstant(NAN);
    dqdd_dq->setConstant(NAN);
    dqdd_dqd->setConstant(NAN);
    m_inv->setConstant(NAN);
    if (dqdd_dforce != nullptr) dqdd_dforce->setConstant(NAN);
    return;
  }
  // 18 columns of derivatives, qdd's right-hand side and a zero column: 20
  // row-major columns are five whole AVX packets per row, where 18 or 19
  // would make Eigen fall back to 2-wide packets for the whole solve.
  Rhs6<20> rhs;
  rhs.leftCols<6>() = numerator;
  rhs.middleCols<6>(6).noalias() = -friction_nspm * H.lazyProduct(H.transpose());
  rhs.middleCols<6>(12).setIdentity();
  rhs.col(18) = H * force + disturbance_n - terms.C_qd - terms.G;
  rhs.col(19).setZero();
  inertia.SolveInPlace<20>(&rhs);
  *qdd = rhs.col(18);
  *dqdd_dq = rhs.leftCols<6>();
  *dqdd_dqd = rhs.middleCols<6>(6);
  *m_inv = rhs.middleCols<6>(12);
  if (dqdd_dforce != nullptr) dqdd_dforce->noalias() = *m_inv * H;
}

}  // namespace stewart
