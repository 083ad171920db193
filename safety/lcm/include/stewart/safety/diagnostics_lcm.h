#pragma once
// SafetyDiagnostics -> stewart::safety_diagnostics_t, for the safety node
// only (the core library has no LCM). Header-only: target stewart_safety_lcm.
// Reusing one message object across steps keeps the string and array
// capacities, so steady-state filling does not allocate.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "stewart/safety/safety_filter.h"
#include "stewart/safety_diagnostics_t.hpp"

namespace stewart::safety {

/// Every variant and its safety_diagnostics_t::VARIANT_* value, in the order
/// of kSafetyVariantNames.
inline constexpr std::array<std::pair<SafetyVariant, std::int8_t>, kSafetyVariantNames.size()>
    kLcmVariants{{
        {SafetyVariant::kClosedForm, safety_diagnostics_t::VARIANT_CLOSED_FORM},
        {SafetyVariant::kPaperRule, safety_diagnostics_t::VARIANT_PAPER_RULE},
        {SafetyVariant::kQpReference, safety_diagnostics_t::VARIANT_QP_REFERENCE},
        {SafetyVariant::kUncomposed, safety_diagnostics_t::VARIANT_UNCOMPOSED},
    }};

inline std::int8_t ToLcmVariant(SafetyVariant v) {
  for (const auto& [variant, value] : kLcmVariants) {
    if (variant == v) return value;
  }
  return safety_diagnostics_t::VARIANT_CLOSED_FORM;
}

/// The variant of a recorded VARIANT_* value; closed form for an unknown one.
inline SafetyVariant FromLcmVariant(std::int8_t value) {
  for (const auto& [variant, v] : kLcmVariants) {
    if (v == value) return variant;
  }
  return SafetyVariant::kClosedForm;
}

/// Fills everything but utime, seq and sample_utime (the node's job).
inline void FillDiagnosticsMessage(const SafetyFilter& filter, const SafetyDiagnostics& d,
                                   safety_diagnostics_t* msg) {
  const ConstraintSet& c = filter.constraints();
  const BarrierEvaluation& b = d.barriers;
  msg->variant = ToLcmVariant(d.variant);
  msg->correction_metric = filter.correction_metric() == CorrectionMetric::kAcceleration
                               ? safety_diagnostics_t::METRIC_ACCELERATION
                               : safety_diagnostics_t::METRIC_FORCE;
  msg->active_case = static_cast<std::int8_t>(d.filter_case);
  msg->infeasible = d.infeasible;
  msg->fallback_reason = d.flags & (kFlagInfeasible | kFlagFallback | kFlagInvalidInput);
  msg->num_position = c.num_position;
  msg->position_names.resize(static_cast<size_t>(c.num_position));
  msg->h_position.resize(static_cast<size_t>(c.num_position));
  msg->alpha_h_position.resize(static_cast<size_t>(c.num_position));
  msg->w_position.resize(static_cast<size_t>(c.num_position));
  msg->mu_position.resize(static_cast<size_t>(c.num_position));
  for (size_t i = 0; i < static_cast<size_t>(c.num_position); ++i) {
    msg->position_names[i] = c.position[i].name;
    msg->h_position[i] = b.h_position[i];
    msg->alpha_h_position[i] = b.alpha_h_position[i];
    msg->w_position[i] = b.w_position[i];
    msg->mu_position[i] = d.mu_position[i];
  }
  msg->num_velocity = c.num_velocity;
  msg->velocity_names.resize(static_cast<size_t>(c.num_velocity));
  msg->h_velocity.resize(static_cast<size_t>(c.num_velocity));
  msg->alpha_h_velocity.resize(static_cast<size_t>(c.num_velocity));
  msg->w_velocity.resize(static_cast<size_t>(c.num_velocity));
  msg->mu_velocity.resize(static_cast<size_t>(c.num_velocity));
  for (size_t i = 0; i < static_cast<size_t>(c.num_velocity); ++i) {
    msg->velocity_names[i] = c.velocity[i].name;
    msg->h_velocity[i] = b.h_velocity[i];
    msg->alpha_h_velocity[i] = b.alpha_h_velocity[i];
    msg->w_velocity[i] = b.w_velocity[i];
    msg->mu_velocity[i] = d.mu_velocity[i];
  }
  msg->h_pos = b.h_pos;
  msg->h_vel = b.h_vel;
  msg->psi_p = b.psi_p;
  msg->psi_v = b.psi_v;
  for (int i = 0; i < 6; ++i) {
    msg->g_p[i] = b.g_p(i);
    msg->g_v[i] = b.g_v(i);
    msg->mu_force[i] = d.mu_force(i);
    msg->f_des[i] = std::isfinite(d.f_des(i)) ? d.f_des(i) : 0.0;  // never NaN on a channel
    msg->f_safe[i] = d.f_safe(i);
  }
  msg->mu_p = d.mu_p;
  msg->mu_v = d.mu_v;
  msg->correction_norm = d.correction_norm;
  msg->compute_ns = d.compute_ns;
  msg->flags = d.flags;
  msg->force_limits = filter.force_limits();
}

}  // namespace stewart::safety
