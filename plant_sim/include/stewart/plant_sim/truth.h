#pragma once
// The physics of the simulated platform when it differs from the stack's
// model (docs/simulation.md, "Truth"). plant_sim, the device emulator and the
// in-process closed loop build their plant from a PlantTruth; the estimator,
// the controller and the filter never see it. Units SI, frames as in
// model/types.h: {B} base, {P} platform.
#include <vector>

#include "stewart/model/actuator_params.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/sensor_params.h"
#include "stewart/model/types.h"

namespace stewart {

/// A rigid payload fixed to the top plate: a point mass (box_m = 0) or a
/// uniform box with edges along {P}'s axes.
struct Payload {
  double mass_kg = 0.0;
  Vector3d position_in_P_m = Vector3d::Zero();  ///< its CoM
  Vector3d box_m = Vector3d::Zero();            ///< edge lengths (m)
};

/// What the model's ActuatorConfig does not describe.
struct ActuatorTruth {
  /// Motor force = gain_i * sat(F_cmd,i): a motor constant or supply error.
  Vector6d force_gain = Vector6d::Ones();
  /// Coulomb (dry) friction magnitude per leg (N), smoothed as
  /// F = -F_c tanh(Ld / kCoulombSpeedScaleMps) so the right-hand side stays
  /// Lipschitz for the integrator.
  Vector6d coulomb_friction_n = Vector6d::Zero();
};
constexpr double kCoulombSpeedScaleMps = 1e-3;

/// Sensor errors the stack's SensorConfig does not model.
struct SensorTruth {
  /// Potentiometer reading before the ADC: scale_i L + offset_i +
  /// nonlinearity sin(pi u), u = (L - l_min) / stroke (a bowed track).
  Vector6d leg_scale = Vector6d::Ones();
  Vector6d leg_offset_m = Vector6d::Zero();
  double leg_nonlinearity_m = 0.0;
  /// IMU: per-axis scale factors and a small rotation of the IMU's axes
  /// against {P} (roll, pitch, yaw of the misalignment, rad).
  Vector3d gyro_scale = Vector3d::Ones();
  Vector3d accel_scale = Vector3d::Ones();
  Vector3d imu_misalignment_rad = Vector3d::Zero();
};

/// Delays between the plant and the stack (s). A sensor sample of instant t
/// reaches the stack at t + sensor_s and the command computed from it acts on
/// the legs at t + sensor_s + command_s; the messages carry t, so the plant
/// models both as one delay of the command's effect.
struct LatencyTruth {
  double sensor_s = 0.0;
  double command_s = 0.0;
  double total_s() const { return sensor_s + command_s; }
};

/// An external wrench on the platform: [force (N); torque (N m)], both in {B}
/// axes, the force acting through the origin of {P}.
struct WrenchStep {
  double start_s = 0.0;
  Vector6d wrench = Vector6d::Zero();
};
struct WrenchPulse {
  double start_s = 0.0;
  double duration_s = 0.0;
  Vector6d wrench = Vector6d::Zero();
};
struct WrenchSinusoid {
  Vector6d amplitude = Vector6d::Zero();
  double frequency_hz = 0.0;
  double phase_rad = 0.0;
};
/// Pushes at Poisson times (rate_hz), each a pulse of duration_s with a force
/// of uniformly random direction and magnitude in [0, max_force_n].
struct RandomPushes {
  double rate_hz = 0.0;
  double max_force_n = 0.0;
  double duration_s = 0.2;
  unsigned seed = 0;
};
struct Disturbance {
  Vector6d constant = Vector6d::Zero();
  std::vector<WrenchStep> steps;  ///< each adds from its start on
  std::vector<WrenchPulse> pulses;
  std::vector<WrenchSinusoid> sinusoids;
  RandomPushes random_pushes;
};

struct PlantTruth {
  PlatformParams platform;  ///< payload already merged (WithPayload)
  ActuatorConfig actuators;
  ActuatorTruth actuator_errors;
  SensorConfig sensors;
  SensorTruth sensor_errors;
  LatencyTruth latency;
  Disturbance disturbance;
  Payload payload;  ///< as given, for reports (already in `platform`)
  Vector6d initial_pose = Vector6d::Zero();
  Vector6d initial_velocity = Vector6d::Zero();
};

/// The platform with a payload rigidly attached: total mass, combined CoM and
/// the inertia tensor about it (parallel-axis theorem), all in {P}.
PlatformParams WithPayload(const PlatformParams& platform, const Payload& payload);

}  // namespace stewart
