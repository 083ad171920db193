#include "stewart/model/shared_dynamics_terms.h"

#include <stdexcept>

namespace stewart {

// A field added to PlatformParams or LegParams changes these sizes: compare
// it in SameParams, or two models that differ in it would share terms.
static_assert(sizeof(LegParams) == 7 * sizeof(double), "compare the new LegParams field below");
static_assert(sizeof(PlatformParams) == (2 * 3 * kNumLegs + 1 + 3 * 3 + 7 + 3) * sizeof(double),
              "compare the new PlatformParams field below");

bool SameParams(const PlatformParams& a, const PlatformParams& b) {
  const LegParams& la = a.leg;
  const LegParams& lb = b.leg;
  return a.base_joints_in_B_m == b.base_joints_in_B_m &&
         a.platform_joints_in_P_m == b.platform_joints_in_P_m &&
         a.platform_mass_kg == b.platform_mass_kg &&
         a.platform_com_in_P_m == b.platform_com_in_P_m &&
         a.platform_inertia_kgm2 == b.platform_inertia_kgm2 &&
         a.platform_inertia_products_kgm2 == b.platform_inertia_products_kgm2 &&
         la.cylinder_mass_kg == lb.cylinder_mass_kg &&
         la.cylinder_com_from_base_m == lb.cylinder_com_from_base_m &&
         la.cylinder_inertia_kgm2 == lb.cylinder_inertia_kgm2 && la.rod_mass_kg == lb.rod_mass_kg &&
         la.rod_com_from_platform_m == lb.rod_com_from_platform_m &&
         la.rod_inertia_kgm2 == lb.rod_inertia_kgm2 &&
         la.actuator_reflected_mass_kg == lb.actuator_reflected_mass_kg &&
         a.leg_min_length_m == b.leg_min_length_m && a.leg_max_length_m == b.leg_max_length_m &&
         a.gravity_mps2 == b.gravity_mps2;
}

void SharedDynamicsTerms::Evaluate(const Vector6d& q, const Vector6d& qd, DynamicsTerms* terms) {
  // NaN never compares equal: a non-finite state is always evaluated anew.
  if (valid_ && q == q_ && qd == qd_) {
    ++hits_;
    *terms = terms_;
    return;
  }
  EvaluateDynamics(params_, q, qd, &terms_);
  q_ = q;
  qd_ = qd;
  valid_ = true;
  ++evaluations_;
  *terms = terms_;
}

std::shared_ptr<SharedDynamicsTerms> AttachSharedTerms(
    const PlatformParams& own, std::shared_ptr<SharedDynamicsTerms> shared) {
  if (shared && !SameParams(own, shared->params())) {
    throw std::invalid_argument(
        "shared model terms: their platform parameters differ from this component's");
  }
  return shared;
}

}  // namespace stewart
