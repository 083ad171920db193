#include "stewart/identify/leg_path.h"

#include <Eigen/LU>

#include "stewart/model/dynamics.h"

namespace stewart::identify {

LegPathTerms LegPathTermsAt(const PlatformParams& model, const Vector6d& q, int leg) {
  PlatformParams without_rotors = model;
  without_rotors.leg.actuator_reflected_mass_kg = 0.0;
  const DynamicsTerms terms = EvaluateDynamics(without_rotors, q, Vector6d::Zero());
  // J_l = H^T; s = J_l^-1 e_i.
  const Eigen::PartialPivLU<Matrix6d> lu(terms.H.transpose());
  const Vector6d s = lu.solve(Vector6d::Unit(leg));
  LegPathTerms out;
  out.inertia_kg = s.dot(terms.M * s);
  out.load_n = s.dot(terms.G);
  return out;
}

}  // namespace stewart::identify
