#include "stewart/safety/constraint_set.h"

#include <cmath>
#include <vector>

#include "stewart/common/check.h"
#include "stewart/model/joint_tolerance.h"
#include "stewart/model/kinematics.h"

namespace stewart::safety {

Vector6d JointToleranceMargin(const PlatformParams& platform, const SafetyConfig& safety) {
  const JointTolerance tolerance{safety.joint_radius_tolerance_m, safety.joint_angle_tolerance_rad};
  if (tolerance.IsZero()) return Vector6d::Zero();
  Vector6d home;
  for (int i = 0; i < kNumAxes; ++i) home(i) = safety.home_pose[static_cast<size_t>(i)];
  // The grid is laid around home (a config built in code may not set it).
  STEWART_CHECK_INPUT(LegLengthsWithinStroke(platform, InverseKinematics(platform, home)),
                      "safety.joint_position_tolerance",
                      "needs the home pose (platform.home_pose) inside the leg stroke");
  // Per translational axis: home, its limits, a lone limit mirrored.
  std::array<std::vector<double>, 3> values;
  for (int a = 0; a < 3; ++a) values[static_cast<size_t>(a)] = {home(a)};
  for (const PositionLimitConfig& l : safety.position_limits) {
    if (l.axis >= 3) continue;
    std::vector<double>& v = values[static_cast<size_t>(l.axis)];
    for (const std::optional<double>& limit : {l.lower, l.upper}) {
      if (limit) v.push_back(*limit);
    }
    if (l.lower.has_value() != l.upper.has_value()) {
      v.push_back(2.0 * home(l.axis) - (l.lower ? *l.lower : *l.upper));
    }
  }
  Vector6d margin = PoseErrorBound(platform, tolerance, home);
  for (double x : values[0]) {
    for (double y : values[1]) {
      for (double z : values[2]) {
        Vector6d q = home;
        q.head<3>() << x, y, z;
        if (!LegLengthsWithinStroke(platform, InverseKinematics(platform, q))) continue;
        margin = margin.cwiseMax(PoseErrorBound(platform, tolerance, q));
      }
    }
  }
  return margin;
}

LegStrokeBand LegStrokeBandOf(const PlatformParams& platform, const LegStrokeLimitConfig& stroke) {
  return {platform.leg_min_length_m + stroke.margin_m, platform.leg_max_length_m - stroke.margin_m};
}

ConstraintSet BuildConstraintSet(const PlatformParams& platform, const SafetyConfig& safety) {
  ConstraintSet c;
  STEWART_CHECK_INPUT(safety.k_position > 0.0, "safety.k_position", "must be positive");
  STEWART_CHECK_INPUT(safety.k_velocity > 0.0, "safety.k_velocity", "must be positive");
  c.k_position = safety.k_position;
  c.k_velocity = safety.k_velocity;
  STEWART_CHECK_INPUT(safety.position_robust_margin_w >= 0.0, "safety.position_robust_margin_w",
                      "must be >= 0");
  STEWART_CHECK_INPUT(safety.velocity_robust_margin_mps2 >= 0.0,
                      "safety.velocity_robust_margin_mps2", "must be >= 0");
  c.position_margin = safety.position_robust_margin_w;
  STEWART_CHECK_INPUT(safety.position_rate_per_s > 0.0, "safety.position_rate_per_s",
                      "must be positive");
  STEWART_CHECK_INPUT(safety.velocity_rate_per_s > 0.0, "safety.velocity_rate_per_s",
                      "must be positive");
  c.position_rate_per_s = safety.position_rate_per_s;
  c.velocity_rate_per_s = safety.velocity_rate_per_s;
  c.velocity_margin = safety.velocity_robust_margin_mps2;
  auto add_position = [&](PositionSource source, int index, double sign, double limit,
                          double alpha_e, double alpha, const std::string& name) {
    STEWART_CHECK_INPUT(c.num_position < kMaxPositionBarriers, "safety.position_limits",
                        "too many position limits (axis listed twice?)");
    STEWART_CHECK_INPUT(alpha_e > 0.0 && alpha > 0.0, "safety constraint " + name,
                        "alpha_e and alpha must be positive");
    c.position[static_cast<size_t>(c.num_position++)] = {source,  index, sign, limit,
                                                         alpha_e, alpha, name};
  };
  c.joint_tolerance_margin = JointToleranceMargin(platform, safety);
  for (const PositionLimitConfig& l : safety.position_limits) {
    const std::string axis(kAxisNames[static_cast<size_t>(l.axis)]);
    const double margin = c.joint_tolerance_margin(l.axis);
    STEWART_CHECK_INPUT(std::isfinite(margin), "safety.joint_position_tolerance",
                        "the pose error is unbounded (a singular pose on the limits' grid)");
    // Home inside the drawn-in limits also leaves room between them.
    const double home = safety.home_pose[static_cast<size_t>(l.axis)];
    STEWART_CHECK_INPUT(
        !(margin > 0.0) ||
            ((!l.lower || *l.lower + margin < home) && (!l.upper || home < *l.upper - margin)),
        "safety.joint_position_tolerance", "draws a " + axis + " limit past the home pose");
    if (l.lower)
      add_position(PositionSource::kAxis, l.axis, 1.0, *l.lower + margin, l.alpha_e, l.alpha,
                   axis + "_lower");
    if (l.upper)
      add_position(PositionSource::kAxis, l.axis, -1.0, *l.upper - margin, l.alpha_e, l.alpha,
                   axis + "_upper");
  }
  if (safety.leg_stroke.enabled) {
    const LegStrokeLimitConfig& s = safety.leg_stroke;
    const LegStrokeBand band = LegStrokeBandOf(platform, s);
    STEWART_CHECK_INPUT(band.lower_m < band.upper_m, "safety.leg_stroke.margin_m",
                        "leaves no stroke");
    for (int i = 0; i < kNumLegs; ++i) {
      const std::string leg = "leg" + std::to_string(i);
      add_position(PositionSource::kLegLength, i, 1.0, band.lower_m, s.alpha_e, s.alpha,
                   leg + "_lower");
      add_position(PositionSource::kLegLength, i, -1.0, band.upper_m, s.alpha_e, s.alpha,
                   leg + "_upper");
    }
  }
  auto add_velocity = [&](PositionSource source, int index, double sign, double limit,
                          double alpha_v, const std::string& name) {
    STEWART_CHECK_INPUT(c.num_velocity < kMaxVelocityBarriers, "safety.velocity_limits",
                        "too many velocity limits (axis listed twice?)");
    STEWART_CHECK_INPUT(alpha_v > 0.0, "safety constraint " + name, "alpha_v must be positive");
    VelocityBarrierSpec& v = c.velocity[static_cast<size_t>(c.num_velocity++)];
    v = VelocityBarrierSpec{};
    v.source = source;
    v.index = index;
    v.sign = sign;
    v.limit = limit;
    v.alpha_v = alpha_v;
    v.name = name;
  };
  for (const VelocityLimitConfig& l : safety.velocity_limits) {
    const std::string axis = std::string(kAxisNames[static_cast<size_t>(l.axis)]) + "d";
    if (l.lower)
      add_velocity(PositionSource::kAxis, l.axis, 1.0, *l.lower, l.alpha_v, axis + "_lower");
    if (l.upper)
      add_velocity(PositionSource::kAxis, l.axis, -1.0, *l.upper, l.alpha_v, axis + "_upper");
  }
  // Recovery barriers: relative degree one in F (unlike the energy barrier,
  // whose F gradient -H^T qd vanishes at rest), so the set stays attractive
  // from outside. kappa doubles as their class-K gain: the position error
  // then obeys h'' + 2 kappa h' + kappa^2 h >= 0 (critically damped).
  const double kappa = safety.recovery_gain_per_s;
  STEWART_CHECK_INPUT(kappa >= 0.0, "safety.recovery_gain_per_s", "must be >= 0");
  // The speed back stays within the velocity limits (else the recovery and
  // velocity barriers would leave no feasible velocity): half the smallest
  // limit of the axis, and for a leg, which moves with every axis, of any
  // translational axis.
  auto slowest_limit = [&](auto on_axis) {
    double slowest = 0.0;
    for (const VelocityLimitConfig& l : safety.velocity_limits) {
      if (!on_axis(l.axis)) continue;
      for (const std::optional<double>& v : {l.lower, l.upper}) {
        if (v && (slowest == 0.0 || std::fabs(*v) < slowest)) slowest = std::fabs(*v);
      }
    }
    return slowest;
  };
  if (kappa > 0.0) {
    const int num_position = c.num_position;
    for (int i = 0; i < num_position; ++i) {
      const PositionBarrierSpec& p = c.position[static_cast<size_t>(i)];
      const bool axis = p.source == PositionSource::kAxis;
      if (!axis && !safety.leg_stroke.recovery) continue;
      const double slowest = axis ? slowest_limit([&](int a) { return a == p.index; })
                                  : slowest_limit([](int a) { return a < 3; });
      add_velocity(p.source, p.index, p.sign, 0.0, kappa, p.name + "_recovery");
      VelocityBarrierSpec& r = c.velocity[static_cast<size_t>(c.num_velocity - 1)];
      r.recovery_of = i;
      r.recovery_gain_per_s = kappa;
      r.recovery_speed = 0.5 * slowest;
      c.has_recovery = true;
      c.has_leg_recovery = c.has_leg_recovery || !axis;
    }
  }
  STEWART_CHECK_INPUT(safety.disturbance_sigma >= 0.0, "safety.disturbance_sigma", "must be >= 0");
  c.disturbance_sigma = safety.use_disturbance_estimate ? safety.disturbance_sigma : 0.0;
  return c;
}

}  // namespace stewart::safety
