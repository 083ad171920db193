#include "stewart/safety/nominal_bound.h"

#include <cmath>
#include <limits>

namespace stewart::safety {

Vector6d NominalAccelerationBound(double sample_period_s, double velocity_step_mps,
                                  double angular_step_radps) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Vector6d max_accel = Vector6d::Constant(kInf);
  if (!(sample_period_s > 0.0)) return max_accel;
  if (velocity_step_mps > 0.0) max_accel.head<3>().setConstant(velocity_step_mps / sample_period_s);
  if (angular_step_radps > 0.0) {
    max_accel.tail<3>().setConstant(angular_step_radps / sample_period_s);
  }
  return max_accel;
}

double BoundNominal(const DynamicsTerms& terms, const Cholesky6& inertia,
                    LegJacobianFactor* h_factor, const Vector6d& leg_speed_mps,
                    double leg_friction_nspm, const Vector6d& disturbance_n,
                    const Vector6d& max_accel, const Vector6d& f_des, Vector6d* f_bounded) {
  *f_bounded = f_des;
  const Vector6d friction_n = LegViscousFriction(leg_friction_nspm, leg_speed_mps);
  const Vector6d qdd_des =
      inertia.Solve<1>(terms.H * (f_des + friction_n) + disturbance_n - terms.C_qd - terms.G);
  if (!qdd_des.allFinite()) return 0.0;
  double scale = 1.0;
  for (int j = 0; j < 6; ++j) {
    const double magnitude = std::abs(qdd_des(j));
    if (magnitude > max_accel(j)) scale = std::min(scale, max_accel(j) / magnitude);
  }
  if (scale == 1.0) return 1.0;
  // InverseDynamics(terms, 0, d) with the step's factor of H: H^-1 (C qd + G - d).
  Vector6d f_zero_accel = terms.C_qd + terms.G - disturbance_n;
  if (!h_factor->Solve(terms.H, &f_zero_accel)) return 0.0;
  f_zero_accel -= friction_n;
  if (!f_zero_accel.allFinite()) return 0.0;
  *f_bounded = f_zero_accel + scale * (f_des - f_zero_accel);
  return scale;
}

}  // namespace stewart::safety
