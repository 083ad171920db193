#include "stewart/config/truth_loader.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <set>

#include "stewart/config/sections.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

constexpr double kDegToRad = 3.141592653589793 / 180.0;
constexpr double kMaxLatencyS = 0.4;  // the message below; Plant's delay queue holds 0.5 s at 1 kHz

// Keys a truth may set, per section: the config's own and the truth's extras.
const std::set<std::string> kPlatformKeys = {"base_joint_radius_m",
                                             "platform_joint_radius_m",
                                             "base_joint_angles_deg",
                                             "platform_joint_angles_deg",
                                             "mass_kg",
                                             "com_m",
                                             "inertia_kgm2",
                                             "gravity_mps2",
                                             "home_pose",
                                             "inertia_products_kgm2",
                                             "payload",
                                             "base_joint_radius_offsets_m",
                                             "platform_joint_radius_offsets_m"};
const std::set<std::string> kLegKeys = {"cylinder_mass_kg",        "cylinder_com_from_base_m",
                                        "cylinder_inertia_kgm2",   "rod_mass_kg",
                                        "rod_com_from_platform_m", "rod_inertia_kgm2"};
const std::set<std::string> kActuatorKeys = {"min_length_m",
                                             "stroke_m",
                                             "force_limit_n",
                                             "viscous_friction_nspm",
                                             "force_lag_s",
                                             "endstop_stiffness_npm",
                                             "endstop_damping_nspm",
                                             "force_gain",
                                             "coulomb_friction_n",
                                             "model",
                                             "motor"};
const std::set<std::string> kSensorKeys = {"rate_hz",
                                           "leg_pot_noise_std_m",
                                           "leg_adc_bits",
                                           "gyro_noise_std_radps",
                                           "gyro_bias_radps",
                                           "accel_noise_std_mps2",
                                           "accel_bias_mps2",
                                           "imu_offset_m",
                                           "has_orientation",
                                           "orientation_noise_std_rad",
                                           "seed",
                                           "leg_scale",
                                           "leg_offset_m",
                                           "leg_nonlinearity_m",
                                           "gyro_scale",
                                           "accel_scale",
                                           "imu_misalignment_deg"};
const std::set<std::string> kLatencyKeys = {"sensor_ms", "command_ms"};
const std::set<std::string> kInitialStateKeys = {"pose", "velocity"};
const std::set<std::string> kDisturbanceKeys = {
    "constant_force_n", "constant_torque_nm", "steps", "pulses", "sinusoids", "random_pushes"};
// A whole stack config works as a truth: its other sections are not physics.
const std::set<std::string> kIgnoredSections = {"controller", "safety", "estimator", "plant_sim",
                                                "hw_bridge",  "rates",  "lcm",       "supervisor",
                                                "guard",      "viewer"};

void CheckKeys(const YAML::Node& node, const std::string& path, const std::set<std::string>& keys) {
  if (!node.IsMap()) throw ConfigError(path, "expected a mapping");
  for (const auto& item : node) {
    const std::string key = item.first.as<std::string>();
    if (keys.count(key) == 0) throw ConfigError(path + "." + key, "unknown key");
  }
}

// A list of N numbers, or one number for all N.
template <int N>
Eigen::Matrix<double, N, 1> VectorOrScalar(const ConfigNode& parent, const YAML::Node& section,
                                           const std::string& key,
                                           const Eigen::Matrix<double, N, 1>& fallback) {
  const YAML::Node node = section[key];
  if (!node.IsDefined() || node.IsNull()) return fallback;
  if (node.IsScalar()) {
    return Eigen::Matrix<double, N, 1>::Constant(parent.Double(key));
  }
  if constexpr (N == 6) {
    return parent.Vec6(key);
  } else {
    return parent.Vec3(key);
  }
}

template <int N>
Eigen::Matrix<double, N, 1> PositiveVector(const ConfigNode& parent, const YAML::Node& section,
                                           const std::string& key,
                                           const Eigen::Matrix<double, N, 1>& fallback) {
  const Eigen::Matrix<double, N, 1> v = VectorOrScalar<N>(parent, section, key, fallback);
  if (!(v.array() > 0.0).all()) parent.Fail(key, "must be positive");
  return v;
}

Vector6d WrenchOf(const ConfigNode& node, const char* force_key, const char* torque_key) {
  Vector6d w = Vector6d::Zero();
  if (node.Has(force_key)) w.head<3>() = node.Vec3(force_key);
  if (node.Has(torque_key)) w.tail<3>() = node.Vec3(torque_key);
  return w;
}

void ApplyJointRadiusOffsets(const ConfigNode& platform, const YAML::Node& section, const char* key,
                             Eigen::Matrix<double, 3, kNumLegs>* joints) {
  if (!platform.Has(key)) return;
  const Vector6d offsets = VectorOrScalar<6>(platform, section, key, Vector6d::Zero());
  for (int i = 0; i < kNumLegs; ++i) {
    const double r = joints->col(i).head<2>().norm();
    if (!(r + offsets(i) > 0.0)) platform.Fail(key, "leaves a joint radius <= 0");
    joints->col(i).head<2>() *= (r + offsets(i)) / r;
  }
}

Payload ParsePayload(const ConfigNode& platform) {
  Payload p;
  if (!platform.Has("payload")) return p;
  const ConfigNode node = platform.Child("payload");
  p.mass_kg = node.NonNegativeDouble("mass_kg");
  if (node.Has("position_m")) p.position_in_P_m = node.Vec3("position_m");
  if (node.Has("box_m")) p.box_m = node.Vec3("box_m");
  if ((p.box_m.array() < 0.0).any()) node.Fail("box_m", "edge lengths must not be negative");
  return p;
}

Disturbance ParseDisturbance(const ConfigNode& root, const YAML::Node& truth) {
  Disturbance d;
  if (!truth["disturbance"].IsDefined()) return d;
  CheckKeys(truth["disturbance"], "truth.disturbance", kDisturbanceKeys);
  const ConfigNode node = root.Child("disturbance");
  d.constant = WrenchOf(node, "constant_force_n", "constant_torque_nm");
  if (node.Has("steps")) {
    for (const ConfigNode& s : node.List("steps")) {
      d.steps.push_back({s.NonNegativeDouble("start_s"), WrenchOf(s, "force_n", "torque_nm")});
    }
  }
  if (node.Has("pulses")) {
    for (const ConfigNode& p : node.List("pulses")) {
      d.pulses.push_back({p.NonNegativeDouble("start_s"), p.PositiveDouble("duration_s"),
                          WrenchOf(p, "force_n", "torque_nm")});
    }
  }
  if (node.Has("sinusoids")) {
    for (const ConfigNode& s : node.List("sinusoids")) {
      WrenchSinusoid w;
      w.amplitude = WrenchOf(s, "force_n", "torque_nm");
      w.frequency_hz = s.PositiveDouble("frequency_hz");
      w.phase_rad = s.Has("phase_deg") ? s.Double("phase_deg") * kDegToRad : 0.0;
      d.sinusoids.push_back(w);
    }
  }
  if (node.Has("random_pushes")) {
    const ConfigNode p = node.Child("random_pushes");
    d.random_pushes.rate_hz = p.NonNegativeDouble("rate_hz");
    d.random_pushes.max_force_n = p.NonNegativeDouble("max_force_n");
    d.random_pushes.duration_s = p.PositiveDouble("duration_s");
    const int seed = p.Has("seed") ? p.Int("seed") : 0;
    if (seed < 0) p.Fail("seed", "must not be negative");
    d.random_pushes.seed = static_cast<unsigned>(seed);
  }
  return d;
}

}  // namespace

PlantTruth ParsePlantTruth(const StackConfig& config, const YAML::Node& config_root,
                           const YAML::Node& truth) {
  if (truth.IsNull() || !truth.IsDefined()) return TruthOfConfig(config);
  if (!truth.IsMap()) throw ConfigError("truth", "expected a mapping");
  // The sections a truth overrides, merged key by key into a copy of the config.
  YAML::Node merged = YAML::Clone(config_root);
  const std::vector<std::pair<std::string, const std::set<std::string>*>> sections = {
      {"platform", &kPlatformKeys},      {"legs", &kLegKeys},
      {"actuators", &kActuatorKeys},     {"sensors", &kSensorKeys},
      {"latency", &kLatencyKeys},        {"initial_state", &kInitialStateKeys},
      {"disturbance", &kDisturbanceKeys}};
  for (const auto& item : truth) {
    const std::string section = item.first.as<std::string>();
    const auto known = std::find_if(sections.begin(), sections.end(),
                                    [&](const auto& s) { return s.first == section; });
    if (known == sections.end()) {
      if (kIgnoredSections.count(section) != 0) continue;
      throw ConfigError("truth." + section, "unknown section");
    }
    CheckKeys(item.second, "truth." + section, *known->second);
    for (const auto& key : item.second) {
      const std::string name = key.first.as<std::string>();
      YAML::Node target = merged[section][name];
      // actuators.motor: key by key too, so a truth can change one motor parameter.
      if (section == "actuators" && name == "motor" && key.second.IsMap() && target.IsMap()) {
        for (const auto& sub : key.second)
          target[sub.first.as<std::string>()] = YAML::Clone(sub.second);
      } else {
        merged[section][name] = YAML::Clone(key.second);
      }
    }
  }
  const ConfigNode root(merged, "truth");
  PlantTruth t;
  t.platform = ParsePlatformParams(root);
  t.actuators = ParseActuatorConfig(root.Child("actuators"));
  t.sensors = ParseSensorConfig(root.Child("sensors"));
  t.sensors.rate_hz = config.sensors.rate_hz;
  t.sensors.seed = config.sensors.seed;

  const ConfigNode platform = root.Child("platform");
  const YAML::Node platform_yaml = merged["platform"];
  ApplyJointRadiusOffsets(platform, platform_yaml, "base_joint_radius_offsets_m",
                          &t.platform.base_joints_in_B_m);
  ApplyJointRadiusOffsets(platform, platform_yaml, "platform_joint_radius_offsets_m",
                          &t.platform.platform_joints_in_P_m);
  if (platform.Has("payload")) {
    CheckKeys(platform_yaml["payload"], "truth.platform.payload",
              {"mass_kg", "position_m", "box_m"});
  }
  t.payload = ParsePayload(platform);
  t.platform = WithPayload(t.platform, t.payload);
  const Eigen::SelfAdjointEigenSolver<Matrix3d> inertia(PlatformInertiaInP(t.platform));
  if (!(inertia.eigenvalues().minCoeff() > 0.0)) {
    platform.Fail("inertia_products_kgm2", "the inertia tensor is not positive definite");
  }

  const ConfigNode actuators = root.Child("actuators");
  const YAML::Node actuators_yaml = merged["actuators"];
  t.actuator_errors.force_gain =
      PositiveVector<6>(actuators, actuators_yaml, "force_gain", Vector6d::Ones());
  t.actuator_errors.coulomb_friction_n =
      VectorOrScalar<6>(actuators, actuators_yaml, "coulomb_friction_n", Vector6d::Zero());
  if ((t.actuator_errors.coulomb_friction_n.array() < 0.0).any()) {
    actuators.Fail("coulomb_friction_n", "must not be negative");
  }

  const ConfigNode sensors = root.Child("sensors");
  const YAML::Node sensors_yaml = merged["sensors"];
  SensorTruth& s = t.sensor_errors;
  s.leg_scale = PositiveVector<6>(sensors, sensors_yaml, "leg_scale", Vector6d::Ones());
  s.leg_offset_m = VectorOrScalar<6>(sensors, sensors_yaml, "leg_offset_m", Vector6d::Zero());
  if (sensors.Has("leg_nonlinearity_m"))
    s.leg_nonlinearity_m = sensors.Double("leg_nonlinearity_m");
  s.gyro_scale = PositiveVector<3>(sensors, sensors_yaml, "gyro_scale", Vector3d::Ones());
  s.accel_scale = PositiveVector<3>(sensors, sensors_yaml, "accel_scale", Vector3d::Ones());
  if (sensors.Has("imu_misalignment_deg")) {
    s.imu_misalignment_rad = sensors.Vec3("imu_misalignment_deg") * kDegToRad;
  }

  if (truth["latency"].IsDefined()) {
    const ConfigNode latency = root.Child("latency");
    for (const char* key : {"sensor_ms", "command_ms"}) {
      if (!latency.Has(key)) continue;
      const double s_value = latency.NonNegativeDouble(key) * 1e-3;
      (std::string(key) == "sensor_ms" ? t.latency.sensor_s : t.latency.command_s) = s_value;
    }
    if (t.latency.total_s() > kMaxLatencyS) {
      latency.Fail("command_ms", "sensor_ms + command_ms must not exceed 400 ms");
    }
  }

  t.initial_pose = config.plant_sim.initial_pose;
  t.initial_velocity = config.plant_sim.initial_velocity;
  if (truth["initial_state"].IsDefined()) {
    const ConfigNode initial = root.Child("initial_state");
    if (initial.Has("pose")) t.initial_pose = initial.Vec6("pose");
    if (initial.Has("velocity")) t.initial_velocity = initial.Vec6("velocity");
  }
  const Vector6d lengths = InverseKinematics(t.platform, t.initial_pose);
  if ((lengths.array() < t.platform.leg_min_length_m).any() ||
      (lengths.array() > t.platform.leg_max_length_m).any()) {
    throw ConfigError("truth.initial_state.pose",
                      "puts a leg outside the actuator stroke of the truth's geometry");
  }
  t.disturbance = ParseDisturbance(root, truth);
  return t;
}

std::string TruthLegModelMismatch(const StackConfig& config, const PlantTruth& truth) {
  if (truth.actuators.kind == config.actuators.kind) return "";
  const auto name = [](ActuatorKind kind) {
    return kind == ActuatorKind::kDcMotor ? "dc_motor" : "ideal_force";
  };
  return std::string("the plant's legs are ") + name(truth.actuators.kind) + ", the stack's " +
         name(config.actuators.kind) +
         ": a truth overrides the config file, not its overlays; if the plant should have the "
         "stack's legs, set actuators.model: " +
         name(config.actuators.kind) + " in the truth";
}

PlantTruth LoadPlantTruth(const StackConfig& config, const std::string& truth_path) {
  if (truth_path.empty()) return TruthOfConfig(config);
  if (config.source_path.empty()) {
    throw ConfigError("<truth>", "a truth file needs the stack config loaded from a file");
  }
  // The base file, not its overlays: overlays change what the stack believes
  // (e.g. identified mass properties), a truth what the simulated plant is.
  return ParsePlantTruth(config, LoadYamlFile(config.source_path), LoadYamlFile(truth_path));
}

}  // namespace stewart
