#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>

#include "stewart/config/config_loader.h"
#include "stewart/config/sections.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

std::string Fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void ValidatePoseInStroke(const PlatformParams& platform, const Vector6d& pose,
                          const std::string& key) {
  const Vector6d lengths = InverseKinematics(platform, pose);
  for (int i = 0; i < kNumLegs; ++i) {
    if (!(lengths(i) >= platform.leg_min_length_m && lengths(i) <= platform.leg_max_length_m)) {
      throw ConfigError(key, "leg " + std::to_string(i) + " length " + Fmt(lengths(i)) +
                                 " m is outside the actuator stroke [" +
                                 Fmt(platform.leg_min_length_m) + ", " +
                                 Fmt(platform.leg_max_length_m) + "] m");
    }
  }
}

StackConfig ParseRoot(const YAML::Node& yaml, const std::string& source) {
  const ConfigNode root(yaml, "");
  StackConfig c;
  c.source_path = source;
  c.platform = ParsePlatformParams(root);
  c.home_pose = root.Child("platform").Vec6("home_pose");
  c.actuators = ParseActuatorConfig(root.Child("actuators"));
  // The stack's box on its input must be one the driver can deliver (a truth
  // may have weaker motors: that is the plant's business, not checked there).
  if (c.actuators.kind == ActuatorKind::kDcMotor &&
      c.actuators.force_limit_n > DcMotorForceAtFullDuty(c.actuators.motor)) {
    root.Child("actuators")
        .Fail("force_limit_n", "exceeds the motor's force at full duty (" +
                                   Fmt(DcMotorForceAtFullDuty(c.actuators.motor)) +
                                   " N from actuators.motor)");
  }
  c.sensors = ParseSensorConfig(root.Child("sensors"));
  c.controller = ParseControllerConfig(root.Child("controller"));
  c.safety = ParseSafetyConfig(root.Child("safety"));
  c.supervisor = ParseSupervisorConfig(root.Child("supervisor"));
  c.estimator = ParseEstimatorConfig(root.Child("estimator"));
  c.plant_sim = ParsePlantSimConfig(root.Child("plant_sim"));
  c.hw_bridge = ParseHwBridgeConfig(root.Child("hw_bridge"), c.actuators);
  c.lcm = ParseLcmConfig(root.Child("lcm"), root.Child("rates"));
  // Optional: a run's config.yaml from before the section (which the replay
  // loads) keeps loading, with the defaults.
  if (root.Has("guard")) c.guard = ParseGuardConfig(root.Child("guard"));
  // One leg damping, the actuators' (screw friction and, for a DC motor, its
  // back-EMF): the controller and the filter model what the plant has (or
  // nothing, when told not to).
  const double leg_damping_nspm = ModelLegDampingNspm(c.actuators);
  c.controller.leg_friction_nspm = c.controller.compensate_friction ? leg_damping_nspm : 0.0;
  c.safety.leg_friction_nspm = c.safety.model_leg_friction ? leg_damping_nspm : 0.0;
  // One sample period of the plant's zero-order hold: the nominal's bound
  // (safety/nominal_bound.h) is a velocity step per period.
  c.safety.sample_period_s = 1.0 / c.sensors.rate_hz;
  for (int i = 0; i < kNumAxes; ++i) c.safety.home_pose[static_cast<size_t>(i)] = c.home_pose(i);
  ValidateStackConfig(c);
  return c;
}

}  // namespace

void ValidateStackConfig(const StackConfig& c) {
  ValidatePoseInStroke(c.platform, c.home_pose, "platform.home_pose");
  ValidatePoseInStroke(c.platform, c.plant_sim.initial_pose, "plant_sim.initial_pose");
  for (std::size_t i = 0; i < c.safety.position_limits.size(); ++i) {
    const PositionLimitConfig& limit = c.safety.position_limits[i];
    const double home = c.home_pose(limit.axis);
    const std::string key = "safety.position_limits[" + std::to_string(i) + "]";
    const std::string axis(kAxisNames[static_cast<size_t>(limit.axis)]);
    if (limit.upper && !(home < *limit.upper)) {
      throw ConfigError(key + ".upper",
                        "excludes the home pose (" + axis + " = " + Fmt(home) + ")");
    }
    if (limit.lower && !(home > *limit.lower)) {
      throw ConfigError(key + ".lower",
                        "excludes the home pose (" + axis + " = " + Fmt(home) + ")");
    }
  }
  // The time window must hold every input gap a process tolerates by its
  // own rules, so it rejects only implausible times, never merely old ones.
  const double window_s = c.lcm.time_plausibility.window_s;
  if (!std::isfinite(window_s)) throw ConfigError("lcm.time_window_s", "must be finite");
  if (!std::isfinite(c.lcm.time_plausibility.max_rate)) {
    throw ConfigError("lcm.max_time_rate", "must be finite");
  }
  const std::pair<const char*, double> tolerated_gaps_s[] = {
      {"safety.stale_age_s", c.safety.stale_age_s},
      {"controller.stale_age_s", c.controller.stale_age_s},
      {"estimator.max_dt_s", c.estimator.max_dt_s},
      {"estimator.command_timeout_s", c.estimator.command_timeout_s},
      {"plant_sim.command_timeout_s", c.plant_sim.command_timeout_s},
      {"hw_bridge.command_timeout_s", c.hw_bridge.command_timeout_s}};
  for (const auto& [key, gap_s] : tolerated_gaps_s) {
    if (!(window_s > gap_s)) {
      throw ConfigError("lcm.time_window_s",
                        Fmt(window_s) + " s must exceed " + key + " (" + Fmt(gap_s) + " s)");
    }
  }
  if (c.safety.leg_stroke.enabled) {
    const Vector6d lengths = InverseKinematics(c.platform, c.home_pose);
    const double margin = c.safety.leg_stroke.margin_m;
    if ((lengths.array() <= c.platform.leg_min_length_m + margin).any() ||
        (lengths.array() >= c.platform.leg_max_length_m - margin).any()) {
      throw ConfigError("safety.leg_stroke.margin_m",
                        "excludes the home pose from the stroke limits");
    }
  }
}

StackConfig ParseStackConfig(const std::string& yaml_text) {
  YAML::Node yaml;
  try {
    yaml = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError("<yaml>", std::string("not valid YAML: ") + e.what());
  }
  return ParseRoot(yaml, "");
}

YAML::Node LoadYamlFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError("<file>", "cannot open '" + path + "'");
  std::stringstream text;
  text << file.rdbuf();
  try {
    return YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw ConfigError("<yaml>", "'" + path + "' is not valid YAML: " + e.what());
  }
}

StackConfig LoadStackConfig(const std::string& path) { return ParseRoot(LoadYamlFile(path), path); }

StackConfig LoadStackConfig(const std::string& path,
                            const std::vector<std::string>& overlay_paths) {
  return ParseRoot(LoadMergedConfigYaml(path, overlay_paths), path);
}

YAML::Node LoadMergedConfigYaml(const std::string& path,
                                const std::vector<std::string>& overlay_paths) {
  YAML::Node merged = LoadYamlFile(path);
  for (const std::string& overlay : overlay_paths) {
    ApplyConfigOverlay(LoadYamlFile(overlay), overlay, &merged);
  }
  return merged;
}

std::string DefaultConfigPath() {
  if (const char* env = std::getenv("STEWART_CONFIG"); env != nullptr && *env != '\0') {
    return env;
  }
  return std::string(STEWART_SOURCE_DIR) + "/config/platform.yaml";
}

}  // namespace stewart
