#include "stewart/stack/random_scenario.h"

#include <algorithm>
#include <optional>
#include <sstream>

#include "stewart/config/scenario_loader.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"
#include "stewart/safety/barriers.h"
#include "stewart/safety/constraint_set.h"

namespace stewart {
namespace {

// Room kept from the stroke ends for a random pose (m): the controller's
// overshoot must not put a leg into an end-stop.
constexpr double kStrokeMarginM = 0.01;
// Room kept inside the filter's position limits for a random start (m): the
// start is inside the safe set, not on its boundary.
constexpr double kStartInsideLimitsM = 0.005;
// Attempts to find a pose inside the stroke before giving up (the sampling box
// is mostly inside, so a handful suffice).
constexpr int kMaxAttempts = 1000;
// Setpoint ranges around home: translations (m) and rotations (rad).
constexpr double kTranslationRangeM = 0.15;
constexpr double kZRangeM = 0.16;
constexpr double kRotationRangeRad = 0.08;

bool InsideStroke(const StackConfig& c, const Vector6d& q) {
  const Vector6d l = InverseKinematics(c.platform, q);
  return (l.array() > c.platform.leg_min_length_m + kStrokeMarginM).all() &&
         (l.array() < c.platform.leg_max_length_m - kStrokeMarginM).all();
}

// `room_m` per axis: how far inside each configured position limit a pose
// must be (m, rad).
bool InsideLimits(const SafetyConfig& s, const Vector6d& q, const Vector6d& room_m) {
  for (const PositionLimitConfig& l : s.position_limits) {
    if (l.upper && q(l.axis) > *l.upper - room_m(l.axis)) return false;
    if (l.lower && q(l.axis) < *l.lower + room_m(l.axis)) return false;
  }
  return true;
}

// A pose inside the stroke; with `room_m`, also that far inside every
// position limit.
Vector6d RandomPose(const StackConfig& c, std::mt19937_64* rng,
                    const std::optional<Vector6d>& room_m) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    Vector6d q = c.home_pose;
    q(0) += kTranslationRangeM * unit(*rng);
    q(1) += kTranslationRangeM * unit(*rng);
    q(2) += kZRangeM * unit(*rng);
    for (int a = 3; a < 6; ++a) q(a) += kRotationRangeRad * unit(*rng);
    if (InsideStroke(c, q) && (!room_m || InsideLimits(c.safety, q, *room_m))) return q;
  }
  return c.home_pose;
}

}  // namespace

RandomRun MakeRandomRun(const StackConfig& config, double duration_s, std::mt19937_64* rng) {
  RandomRun run;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // 3 to 8 steps of random length; every pose inside the stroke, each one
  // inside or beyond the limits as it falls.
  const int steps = 3 + static_cast<int>(unit(*rng) * 6.0);
  std::vector<double> starts{0.0};
  for (int i = 1; i < steps; ++i) starts.push_back(unit(*rng) * duration_s);
  std::sort(starts.begin(), starts.end());
  YAML::Node yaml;
  yaml["name"] = "random";
  yaml["description"] = "random setpoint steps inside and beyond the limits";
  yaml["duration_s"] = duration_s;
  YAML::Node segments(YAML::NodeType::Sequence);
  for (int i = 0; i <= steps; ++i) {
    const bool last = i == steps;
    const Vector6d q_des = last ? config.home_pose : RandomPose(config, rng, std::nullopt);
    YAML::Node segment;
    segment["start_s"] = last ? duration_s : starts[static_cast<size_t>(i)];
    segment["type"] = "step";
    YAML::Node q(YAML::NodeType::Sequence);
    for (int a = 0; a < 6; ++a) q.push_back(q_des(a));
    q.SetStyle(YAML::EmitterStyle::Flow);
    segment["q_des"] = q;
    segment.SetStyle(YAML::EmitterStyle::Flow);
    segments.push_back(segment);
  }
  yaml["segments"] = segments;
  run.scenario_yaml = yaml;
  std::ostringstream text;
  text << yaml;
  run.scenario = ParseScenario(text.str(), "random");

  // The filter's position limits are the configured ones drawn in by the
  // joints' tolerance: a start between the two would begin outside the safe
  // set the filter keeps.
  const safety::ConstraintSet constraints =
      safety::BuildConstraintSet(config.platform, config.safety);
  const Vector6d start_room_m = constraints.joint_tolerance_margin.array() + kStartInsideLimitsM;
  run.initial_pose = RandomPose(config, rng, start_room_m);
  // A velocity the energy barriers have room for (heavy rotors near a limit
  // may not); after kMaxAttempts draws, at rest.
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    for (const VelocityLimitConfig& l : config.safety.velocity_limits) {
      const double bound = 0.5 * std::min(l.upper ? *l.upper : 1e9, l.lower ? -*l.lower : 1e9);
      run.initial_velocity(l.axis) = bound * (2.0 * unit(*rng) - 1.0);
    }
    if (InsideSafeSet(config.platform, constraints, run.initial_pose, run.initial_velocity)) {
      return run;
    }
  }
  run.initial_velocity.setZero();
  return run;
}

bool InsideSafeSet(const PlatformParams& platform, const safety::ConstraintSet& constraints,
                   const Vector6d& q, const Vector6d& qd) {
  const DynamicsTerms terms = EvaluateDynamics(platform, q, qd);
  safety::BarrierEvaluation e;
  safety::EvaluateBarriers(constraints, q, qd, terms, Vector6d::Zero(), &e);
  for (int i = 0; i < constraints.num_position; ++i) {
    if (!(e.h_position[static_cast<size_t>(i)] >= 0.0)) return false;
  }
  for (int i = 0; i < constraints.num_velocity; ++i) {
    const size_t k = static_cast<size_t>(i);
    if (constraints.velocity[k].recovery_of < 0 && !(e.h_velocity[k] >= 0.0)) return false;
  }
  return true;
}

}  // namespace stewart
