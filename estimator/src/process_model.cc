#include "stewart/estimator/process_model.h"

#include <Eigen/Cholesky>

#include "stewart/model/dynamics.h"

namespace stewart {
namespace {
// Forward-difference step: q is O(0.1) m or rad and qdd smooth in it; the
// O(h) error is far below what the covariance propagation needs.
constexpr double kFdStep = 1e-6;
}  // namespace

Vector6d DynamicsAcceleration(const PlatformParams& params, double friction_nspm, const Vector6d& q,
                              const Vector6d& qd, const Vector6d& force_n) {
  DynamicsTerms terms;
  EvaluateDynamics(params, q, qd, &terms);
  return ForwardDynamics(terms, force_n - friction_nspm * (terms.H.transpose() * qd));
}

void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const Vector6d& qd, const Vector6d& force_n,
                                   Vector6d* qdd, Matrix6d* dqdd_dq, Matrix6d* dqdd_dqd) {
  DynamicsTerms terms;
  EvaluateDynamics(params, q, qd, &terms);
  const Vector6d leg_speed_mps = terms.H.transpose() * qd;
  *qdd = ForwardDynamics(terms, force_n - friction_nspm * leg_speed_mps);
  Vector6d x = q;
  for (int i = 0; i < 6; ++i) {
    x(i) += kFdStep;
    dqdd_dq->col(i) =
        (DynamicsAcceleration(params, friction_nspm, x, qd, force_n) - *qdd) / kFdStep;
    x(i) = q(i);
  }
  // dqdd/dqd = -M^-1 (c_v H H^T + d(C qd)/dqd). The Coriolis part is O(|qd|)
  // (C qd is quadratic in qd): ~m |qd| / L ~ 0.05 kg/s at the scenario's
  // speeds against c_v |H H^T| ~ 2 N s/m for the friction, so it is left out.
  *dqdd_dqd = -friction_nspm * terms.M.llt().solve(terms.H * terms.H.transpose());
}

}  // namespace stewart
