#pragma once
// SafetyDiagnostics -> stewart::safety_diagnostics_t, for the safety node
// and replay (the core library has no LCM). Header-only: target stewart_safety_lcm.
// Reusing one message object across steps keeps the string and array
// capacities, so steady-state filling does not allocate.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "stewart/safety/safety_filter.h"
#include "stewart/safety/safety_process.h"
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

/// The value `table` gives `e`; its first entry's for one it lacks.
template <typename Enum, std::size_t N>
std::int8_t LcmValueOf(const std::array<std::pair<Enum, std::int8_t>, N>& table, Enum e) {
  for (const auto& [key, value] : table) {
    if (key == e) return value;
  }
  return table[0].second;
}

inline std::int8_t ToLcmVariant(SafetyVariant v) { return LcmValueOf(kLcmVariants, v); }

/// Every correction metric and its safety_diagnostics_t::METRIC_* value, in
/// the order of kCorrectionMetricNames.
inline constexpr std::array<std::pair<CorrectionMetric, std::int8_t>, kCorrectionMetricNames.size()>
    kLcmMetrics{{
        {CorrectionMetric::kForce, safety_diagnostics_t::METRIC_FORCE},
        {CorrectionMetric::kAcceleration, safety_diagnostics_t::METRIC_ACCELERATION},
        {CorrectionMetric::kTaskAcceleration, safety_diagnostics_t::METRIC_TASK_ACCELERATION},
    }};

inline std::int8_t ToLcmMetric(CorrectionMetric m) { return LcmValueOf(kLcmMetrics, m); }

/// The variant of a recorded VARIANT_* value; closed form for an unknown one.
inline SafetyVariant FromLcmVariant(std::int8_t value) {
  for (const auto& [variant, v] : kLcmVariants) {
    if (v == value) return variant;
  }
  return SafetyVariant::kClosedForm;
}

/// The per-barrier fields of one barrier group of safety_diagnostics_t
/// (position or velocity).
struct DiagnosticsGroupFields {
  std::int32_t* num;
  std::vector<std::string>* names;
  std::vector<double>* h;
  std::vector<double>* alpha_h;
  std::vector<double>* w;
  std::vector<double>* mu;
};

inline DiagnosticsGroupFields PositionGroup(safety_diagnostics_t* msg) {
  return {&msg->num_position,     &msg->position_names, &msg->h_position,
          &msg->alpha_h_position, &msg->w_position,     &msg->mu_position};
}

inline DiagnosticsGroupFields VelocityGroup(safety_diagnostics_t* msg) {
  return {&msg->num_velocity,     &msg->velocity_names, &msg->h_velocity,
          &msg->alpha_h_velocity, &msg->w_velocity,     &msg->mu_velocity};
}

/// The first `n` barriers of a group: their names and their values of one
/// step. Resizing keeps the vectors' capacities.
template <typename Specs, typename Values>
void FillGroup(int n, const Specs& specs, const Values& h, const Values& alpha_h, const Values& w,
               const Values& mu, const DiagnosticsGroupFields& group) {
  const size_t count = static_cast<size_t>(n);
  *group.num = n;
  for (std::vector<double>* values : {group.h, group.alpha_h, group.w, group.mu}) {
    values->resize(count);
  }
  group.names->resize(count);
  for (size_t i = 0; i < count; ++i) {
    (*group.names)[i] = specs[i].name;
    (*group.h)[i] = h[i];
    (*group.alpha_h)[i] = alpha_h[i];
    (*group.w)[i] = w[i];
    (*group.mu)[i] = mu[i];
  }
}

/// Fills everything but utime, seq and sample_utime (the node's job).
inline void FillDiagnosticsMessage(const SafetyFilter& filter, const SafetyDiagnostics& d,
                                   safety_diagnostics_t* msg) {
  const ConstraintSet& c = filter.constraints();
  const BarrierEvaluation& b = d.barriers;
  msg->variant = ToLcmVariant(d.variant);
  msg->correction_metric = ToLcmMetric(filter.correction_metric());
  msg->active_case = static_cast<std::int8_t>(d.filter_case);
  msg->infeasible = d.infeasible;
  msg->fallback_reason = d.flags & (kFlagInfeasible | kFlagFallback | kFlagInvalidInput);
  FillGroup(c.num_position, c.position, b.h_position, b.alpha_h_position, b.w_position,
            d.mu_position, PositionGroup(msg));
  FillGroup(c.num_velocity, c.velocity, b.h_velocity, b.alpha_h_velocity, b.w_velocity,
            d.mu_velocity, VelocityGroup(msg));
  msg->h_pos = b.h_pos;
  msg->h_vel = b.h_vel;
  msg->psi_p = b.psi_p;
  msg->psi_v = b.psi_v;
  for (int i = 0; i < 6; ++i) {
    msg->g_p[i] = b.g_p(i);
    msg->g_v[i] = b.g_v(i);
    msg->mu_force[i] = d.mu_force(i);
    msg->f_des[i] = std::isfinite(d.f_des(i)) ? d.f_des(i) : 0.0;  // never NaN on a channel
    msg->f_nominal[i] = std::isfinite(d.f_nominal(i)) ? d.f_nominal(i) : 0.0;
    msg->f_safe[i] = d.f_safe(i);
  }
  msg->mu_p = d.mu_p;
  msg->mu_v = d.mu_v;
  msg->correction_norm = d.correction_norm;
  msg->nominal_scale = d.nominal_scale;
  msg->compute_ns = d.compute_ns;
  msg->flags = d.flags;
  msg->force_limits = filter.force_limits();
}

/// The diagnostics message of one output of SafetyProcess, as the node
/// publishes it beside the safe command.
inline void FillDiagnosticsMessage(const SafetyFilter& filter, const SafetyOutput& out,
                                   safety_diagnostics_t* msg) {
  FillDiagnosticsMessage(filter, *out.diagnostics, msg);
  msg->utime = out.command.utime;
  msg->seq = out.command.seq;
  msg->sample_utime = out.command.sample_utime;
  msg->fallback_reason |= out.fallback_reason;
}

}  // namespace stewart::safety
