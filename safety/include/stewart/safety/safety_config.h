#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "stewart/common/enum_table.h"

namespace stewart {

/// Position limit on one pose axis: h = upper - q_j or h = q_j - lower.
struct PositionLimitConfig {
  int axis = 0;  ///< index into q
  std::optional<double> lower, upper;
  double alpha_e = 1.0;  ///< energy weight of the energy-based barrier (N, J/m)
  double alpha = 1.0;    ///< class-K gain (1/s)
};

/// Velocity limit on one pose axis: h_v = upper - qd_j or h_v = qd_j - lower.
struct VelocityLimitConfig {
  int axis = 0;
  std::optional<double> lower, upper;
  double alpha_v = 1.0;  ///< class-K gain (1/s)
};

struct LegStrokeLimitConfig {
  bool enabled = false;
  double margin_m = 0.0;  ///< kept from each stroke end
  double alpha_e = 1.0;
  double alpha = 1.0;
  /// Each leg-stroke barrier gets a recovery barrier (with
  /// recovery_gain_per_s > 0): a leg beyond the band is steered back
  /// (docs/safety.md, "Outside the safe set").
  bool recovery = true;
};

/// kUncomposed: every barrier its own condition, no LSE (docs/safety.md,
/// "The un-composed QP"), to measure what the composition costs.
enum class SafetyVariant { kClosedForm, kPaperRule, kQpReference, kUncomposed };
inline constexpr EnumTable<SafetyVariant, 4> kSafetyVariantNames{{{
    {SafetyVariant::kClosedForm, "closed_form"},
    {SafetyVariant::kPaperRule, "paper"},
    {SafetyVariant::kQpReference, "qp"},
    {SafetyVariant::kUncomposed, "uncomposed"},
}}};

enum class SafetyFallback { kHold, kZero };
inline constexpr EnumTable<SafetyFallback, 2> kSafetyFallbackNames{{{
    {SafetyFallback::kHold, "hold"},
    {SafetyFallback::kZero, "zero"},
}}};

/// How the filter measures the size of its correction F* - F_des
/// (docs/safety.md, "Correction metric"):
///   kForce:        ||F - F_des||^2                   (the paper's QP)
///   kAcceleration: (qdd - qdd_des)^T M (qdd - qdd_des)
///                  = (F - F_des)^T H^T M^-1 H (F - F_des)   (Gauss's least constraint)
///   kTaskAcceleration: ||qdd - qdd_des||^2
///                  = (F - F_des)^T H^T M^-2 H (F - F_des)
enum class CorrectionMetric { kForce, kAcceleration, kTaskAcceleration };
inline constexpr EnumTable<CorrectionMetric, 3> kCorrectionMetricNames{{{
    {CorrectionMetric::kForce, "force"},
    {CorrectionMetric::kAcceleration, "acceleration"},
    {CorrectionMetric::kTaskAcceleration, "task_acceleration"},
}}};

/// `safety`: the CBF filter's constraints and parameters.
struct SafetyConfig {
  SafetyVariant variant = SafetyVariant::kClosedForm;
  double k_position = 1.0;  ///< LSE sharpness of the position group
  double k_velocity = 1.0;  ///< LSE sharpness of the velocity group
  std::vector<PositionLimitConfig> position_limits;
  std::vector<VelocityLimitConfig> velocity_limits;
  LegStrokeLimitConfig leg_stroke;
  bool force_limits_enabled = false;
  double stale_age_s = 0.02;
  SafetyFallback fallback = SafetyFallback::kHold;
  /// Time constant of the "hold" safe stop: qdd = -qd / stop_time_s (s).
  /// Optional key, default 0.2 s.
  double stop_time_s = 0.2;
  /// Optional key `correction_metric` (force | acceleration), default force.
  CorrectionMetric correction_metric = CorrectionMetric::kForce;
  /// Viscous leg friction the filter's dynamics include (N per m/s of leg
  /// speed): actuators.viscous_friction_nspm when the optional key
  /// `model_leg_friction` is true (default), else 0. Set by ParseStackConfig.
  bool model_leg_friction = true;
  /// Robustness margins (optional keys, default 0): the conditions become
  /// Psi_v >= velocity_robust_margin_mps2 and Psi_p >= position_robust_margin_w,
  /// so a model or estimation error up to the margin (e.g. gravity through an
  /// attitude error, g * 0.1 mrad = 1 mm/s^2) cannot hold the state outside.
  double velocity_robust_margin_mps2 = 0.0;
  double position_robust_margin_w = 0.0;
  /// Optional key `joint_position_tolerance: {radius_m, angle_deg}`: how well
  /// the joint centres are known. The axis position limits are drawn in by
  /// the worst pose error it allows (model/joint_tolerance.h; docs/safety.md,
  /// "Joint tolerance"). Stored in m and rad; default 0: no margin.
  double joint_radius_tolerance_m = 0.0;
  double joint_angle_tolerance_rad = 0.0;
  /// The pose the limit faces are sampled around for that margin (the
  /// config's platform.home_pose, set by ParseStackConfig).
  std::array<double, 6> home_pose{};
  double leg_friction_nspm = 0.0;
  /// Optional key: kappa of the recovery barriers h_r = sign qd_j + kappa h(q)
  /// of the axis position limits (1/s; docs/safety.md "Outside the safe
  /// set"); 0 leaves them out. Default 20: inactive more than
  /// (velocity limit) / kappa, under 1 mm, inside a position limit.
  double recovery_gain_per_s = 20.0;
  /// Optional keys: gamma of the composed conditions Psi = dh_c + gamma h_c
  /// (1/s), default 1 as in the paper (docs/safety.md, "Model error").
  double position_rate_per_s = 1.0;
  double velocity_rate_per_s = 1.0;
  /// Optional keys: use the state's disturbance estimate d (model/disturbance.h)
  /// in every barrier derivative, and take each derivative at the worst d
  /// within disturbance_sigma standard deviations of it (docs/safety.md,
  /// "Model error").
  bool use_disturbance_estimate = true;
  double disturbance_sigma = 3.0;
  /// Optional keys: the largest velocity change one sample period of the
  /// nominal command may ask of the model (nominal_bound.h; docs/safety.md,
  /// "One sample period"): x, y, z (m/s) and Euler angles (rad/s). 0 turns
  /// an axis group's bound off.
  double per_period_velocity_step_mps = 0.001;
  double per_period_angular_step_radps = 0.01;
  /// The plant's zero-order-hold period T (s): 1 / sensors.rate_hz, set by
  /// ParseStackConfig. 0 (a config built in code) turns the bound off.
  double sample_period_s = 0.0;
  /// Optional key: how long a lift at drive-on goes unanswered (s): the
  /// sample period plus the actuators' latency the stack allows for. The
  /// drive-on hold (SafetyFilter::DriveOnCommand) lets the worst vertical
  /// model error reach the z velocity limit in this time, not sooner; 0 (a
  /// lift answered at once) leaves the hold as the model's (docs/safety.md,
  /// "Drive-on").
  double drive_on_response_s = 0.0;
  /// Optional key `check_each_barrier` (default true), variants closed_form
  /// and qp: the composed answer is checked against every barrier's own
  /// condition, and where it breaks one the un-composed QP answers that step
  /// (kFlagPerBarrier; docs/safety.md, "Each barrier checked").
  bool check_each_barrier = true;
};

inline std::string ToString(SafetyVariant variant) {
  return std::string(kSafetyVariantNames.Name(variant));
}
/// Throws InputError (an std::invalid_argument) listing the names.
inline SafetyVariant ParseSafetyVariant(const std::string& name) {
  return kSafetyVariantNames.Parse(name, "safety variant");
}
inline std::string ToString(CorrectionMetric metric) {
  return std::string(kCorrectionMetricNames.Name(metric));
}
inline CorrectionMetric ParseCorrectionMetric(const std::string& name) {
  return kCorrectionMetricNames.Parse(name, "correction metric");
}

}  // namespace stewart
