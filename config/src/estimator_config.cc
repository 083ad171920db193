#include <climits>

#include "stewart/config/sections.h"

namespace stewart {

EstimatorConfig ParseEstimatorConfig(const ConfigNode& estimator) {
  EstimatorConfig e;
  e.process_model =
      estimator.Choice("process_model", {"dynamics", "constant_velocity"}) == "dynamics"
          ? EstimatorProcessModel::kDynamics
          : EstimatorProcessModel::kConstantVelocity;
  e.process_accel_std_mps2 = estimator.PositiveDouble("process_accel_std_mps2");
  e.process_angaccel_std_radps2 = estimator.PositiveDouble("process_angaccel_std_radps2");
  e.dynamics_accel_std_mps2 = estimator.PositiveDouble("dynamics_accel_std_mps2");
  if (estimator.Has("accel_update_dynamics_std_mps2")) {
    e.accel_update_dynamics_std_mps2 = estimator.PositiveDouble("accel_update_dynamics_std_mps2");
  }
  e.dynamics_angaccel_std_radps2 = estimator.PositiveDouble("dynamics_angaccel_std_radps2");
  e.gyro_bias_walk_radps_per_sqrt_s =
      estimator.NonNegativeDouble("gyro_bias_walk_radps_per_sqrt_s");
  if (estimator.Has("gyro_bias_walk_per_speed")) {
    e.gyro_bias_walk_per_speed = estimator.NonNegativeDouble("gyro_bias_walk_per_speed");
  }
  e.initial_velocity_std_mps = estimator.PositiveDouble("initial_velocity_std_mps");
  e.initial_angular_rate_std_radps = estimator.PositiveDouble("initial_angular_rate_std_radps");
  e.initial_gyro_bias_std_radps = estimator.PositiveDouble("initial_gyro_bias_std_radps");
  e.initial_accel_bias_std_mps2 = estimator.NonNegativeDouble("initial_accel_bias_std_mps2");
  e.accel_bias_walk_mps2_per_sqrt_s =
      estimator.NonNegativeDouble("accel_bias_walk_mps2_per_sqrt_s");
  if (estimator.Has("accel_bias_walk_per_speed")) {
    e.accel_bias_walk_per_speed = estimator.NonNegativeDouble("accel_bias_walk_per_speed");
  }
  if (estimator.Has("accel_bias_axes")) {
    e.estimate_accel_bias_z = estimator.Choice("accel_bias_axes", {"xyz", "xy"}) == "xyz";
  }
  e.leg_noise_inflation = estimator.PositiveDouble("leg_noise_inflation");
  e.use_accelerometer = estimator.Bool("use_accelerometer");
  e.gating_chi2 = estimator.PositiveDouble("gating_chi2");
  e.divergence_rejections =
      estimator.IntInRange("divergence_rejections", 1, INT_MAX, "must be >= 1");
  e.max_dt_s = estimator.PositiveDouble("max_dt_s");
  e.command_timeout_s = estimator.PositiveDouble("command_timeout_s");
  if (estimator.Has("command_latency_s")) {
    e.command_latency_s = estimator.NonNegativeDouble("command_latency_s");
  }
  if (estimator.Has("command_latency_allowance_s")) {
    e.command_latency_allowance_s = estimator.NonNegativeDouble("command_latency_allowance_s");
  }
  e.settle_samples = estimator.IntInRange("settle_samples", 0, INT_MAX, "must not be negative");
  e.max_gyro_radps = estimator.PositiveDouble("max_gyro_radps");
  e.max_accel_mps2 = estimator.PositiveDouble("max_accel_mps2");
  e.leg_range_margin_m = estimator.NonNegativeDouble("leg_range_margin_m");
  e.perfect_state = estimator.Bool("perfect_state");
  if (estimator.Has("disturbance")) {
    const ConfigNode d = estimator.Child("disturbance");
    e.estimate_disturbance = d.Bool("enabled");
    e.disturbance_walk_n_per_sqrt_s = d.PositiveDouble("walk_n_per_sqrt_s");
    e.disturbance_walk_nm_per_sqrt_s = d.PositiveDouble("walk_nm_per_sqrt_s");
    e.initial_disturbance_std_n = d.PositiveDouble("initial_std_n");
    e.initial_disturbance_std_nm = d.PositiveDouble("initial_std_nm");
    e.disturbance_jump_std_n = d.NonNegativeDouble("jump_std_n");
    e.disturbance_jump_std_nm = d.NonNegativeDouble("jump_std_nm");
    e.disturbance_jump_after_samples =
        d.IntInRange("jump_after_samples", 1, INT_MAX, "must be >= 1");
    if (d.Has("early_jump_calm_samples")) {
      e.disturbance_early_jump_calm_samples =
          d.IntInRange("early_jump_calm_samples", 0, INT_MAX, "must not be negative (0: off)");
    }
    if (d.Has("early_jump_max_step_n")) {
      e.disturbance_early_jump_max_step_n = d.PositiveDouble("early_jump_max_step_n");
    }
    if (d.Has("force_change_std")) {
      e.disturbance_force_change_std = d.NonNegativeDouble("force_change_std");
    }
    if (d.Has("force_change_cap_n")) {
      e.disturbance_force_change_cap_n = d.PositiveDouble("force_change_cap_n");
    }
    if (d.Has("friction_flip_std_n")) {
      e.disturbance_friction_flip_std_n = d.NonNegativeDouble("friction_flip_std_n");
    }
    if (d.Has("friction_flip_speed_mps")) {
      e.disturbance_friction_flip_speed_mps = d.NonNegativeDouble("friction_flip_speed_mps");
    }
    if (e.estimate_disturbance && e.process_model != EstimatorProcessModel::kDynamics) {
      d.Fail("enabled", "needs estimator.process_model: dynamics (d acts through the dynamics)");
    }
  }
  return e;
}

}  // namespace stewart
