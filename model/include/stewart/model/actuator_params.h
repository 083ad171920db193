#pragma once
// The legs' actuators as the model sees them (config section `actuators`).

namespace stewart {

struct ActuatorConfig {
  double min_length_m = 0.0;
  double stroke_m = 0.0;
  double force_limit_n = 0.0;          ///< |F_i| <= this
  double viscous_friction_nspm = 0.0;  ///< N per (m/s) of leg speed
  double force_lag_s = 0.0;            ///< first-order lag, 0 = none
  double endstop_stiffness_npm = 0.0;
  double endstop_damping_nspm = 0.0;
};

}  // namespace stewart
