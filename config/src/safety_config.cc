#include <cmath>
#include <stdexcept>

#include "stewart/config/sections.h"

namespace stewart {
namespace {

int ParseAxis(const ConfigNode& node) {
  const std::string name = node.Choice("axis", {"x", "y", "z", "phi", "theta", "psi"});
  for (int i = 0; i < kNumAxes; ++i) {
    if (kAxisNames[static_cast<size_t>(i)] == name) return i;
  }
  return 0;  // unreachable: Choice validated the name
}

template <typename Limit>
void ParseBounds(const ConfigNode& node, Limit* limit) {
  limit->lower = node.OptionalDouble("lower");
  limit->upper = node.OptionalDouble("upper");
  if (!limit->lower && !limit->upper) node.Fail("upper", "give lower, upper or both");
  if (limit->lower && limit->upper && !(*limit->lower < *limit->upper)) {
    node.Fail("lower", "must be below upper");
  }
}

}  // namespace

SafetyConfig ParseSafetyConfig(const ConfigNode& safety) {
  SafetyConfig s;
  s.variant = safety.EnumValue("variant", kSafetyVariantNames);
  s.k_position = safety.PositiveDouble("k_position");
  s.k_velocity = safety.PositiveDouble("k_velocity");
  for (const ConfigNode& node : safety.List("position_limits")) {
    PositionLimitConfig limit;
    limit.axis = ParseAxis(node);
    ParseBounds(node, &limit);
    limit.alpha_e = node.PositiveDouble("alpha_e");
    limit.alpha = node.PositiveDouble("alpha");
    s.position_limits.push_back(limit);
  }
  for (const ConfigNode& node : safety.List("velocity_limits")) {
    VelocityLimitConfig limit;
    limit.axis = ParseAxis(node);
    ParseBounds(node, &limit);
    if (limit.upper && !(*limit.upper > 0.0)) {
      node.Fail("upper", "must be positive: standing still has to be safe");
    }
    if (limit.lower && !(*limit.lower < 0.0)) {
      node.Fail("lower", "must be negative: standing still has to be safe");
    }
    limit.alpha_v = node.PositiveDouble("alpha_v");
    s.velocity_limits.push_back(limit);
  }
  const ConfigNode leg = safety.Child("leg_stroke");
  s.leg_stroke.enabled = leg.Bool("enabled");
  s.leg_stroke.margin_m = leg.NonNegativeDouble("margin_m");
  s.leg_stroke.alpha_e = leg.PositiveDouble("alpha_e");
  s.leg_stroke.alpha = leg.PositiveDouble("alpha");
  if (leg.Has("recovery")) s.leg_stroke.recovery = leg.Bool("recovery");
  s.force_limits_enabled = safety.Bool("force_limits_enabled");
  s.stale_age_s = safety.PositiveDouble("stale_age_s");
  s.fallback = safety.EnumValue("fallback", kSafetyFallbackNames);
  if (const std::optional<double> stop = safety.OptionalDouble("stop_time_s")) {
    if (!(*stop > 0.0)) safety.Fail("stop_time_s", "must be positive");
    s.stop_time_s = *stop;
  }
  if (safety.Has("drive_on_response_s")) {
    s.drive_on_response_s = safety.NonNegativeDouble("drive_on_response_s");
  }
  if (safety.Has("correction_metric")) {
    s.correction_metric = safety.EnumValue("correction_metric", kCorrectionMetricNames);
  }
  if (safety.Has("velocity_robust_margin_mps2")) {
    s.velocity_robust_margin_mps2 = safety.NonNegativeDouble("velocity_robust_margin_mps2");
  }
  if (safety.Has("position_robust_margin_w")) {
    s.position_robust_margin_w = safety.NonNegativeDouble("position_robust_margin_w");
  }
  if (safety.Has("joint_position_tolerance")) {
    const ConfigNode tolerance = safety.Child("joint_position_tolerance");
    s.joint_radius_tolerance_m = tolerance.NonNegativeDouble("radius_m");
    s.joint_angle_tolerance_rad = tolerance.NonNegativeDouble("angle_deg") * M_PI / 180.0;
  }
  if (safety.Has("model_leg_friction")) s.model_leg_friction = safety.Bool("model_leg_friction");
  if (safety.Has("position_rate_per_s")) {
    s.position_rate_per_s = safety.PositiveDouble("position_rate_per_s");
  }
  if (safety.Has("velocity_rate_per_s")) {
    s.velocity_rate_per_s = safety.PositiveDouble("velocity_rate_per_s");
  }
  if (safety.Has("recovery_gain_per_s")) {
    s.recovery_gain_per_s = safety.NonNegativeDouble("recovery_gain_per_s");
  }
  if (safety.Has("use_disturbance_estimate")) {
    s.use_disturbance_estimate = safety.Bool("use_disturbance_estimate");
  }
  if (safety.Has("disturbance_sigma")) {
    s.disturbance_sigma = safety.NonNegativeDouble("disturbance_sigma");
  }
  if (safety.Has("per_period_velocity_step_mps")) {
    s.per_period_velocity_step_mps = safety.NonNegativeDouble("per_period_velocity_step_mps");
  }
  if (safety.Has("per_period_angular_step_radps")) {
    s.per_period_angular_step_radps = safety.NonNegativeDouble("per_period_angular_step_radps");
  }
  if (safety.Has("check_each_barrier")) {
    s.check_each_barrier = safety.Bool("check_each_barrier");
  }
  return s;
}

}  // namespace stewart
