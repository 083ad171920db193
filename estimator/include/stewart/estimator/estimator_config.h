#pragma once

#include <limits>

namespace stewart {

/// Process model of the EKF (docs/estimator.md explains the choice).
enum class EstimatorProcessModel {
  kDynamics,          ///< qdd = M^-1 (H F - C qd - G), F = applied safe command
  kConstantVelocity,  ///< qdd = 0 with white acceleration noise
};

/// `estimator`: EKF tuning. Sensor noise itself comes from `sensors`.
struct EstimatorConfig {
  EstimatorProcessModel process_model = EstimatorProcessModel::kConstantVelocity;
  /// Constant-velocity model (and the dynamics model without a fresh command):
  /// std of the acceleration, white over one sample (m/s^2, rad/s^2).
  double process_accel_std_mps2 = 0.2;
  double process_angaccel_std_radps2 = 0.5;
  /// Dynamics model: std of the model error as an acceleration (m/s^2),
  /// white over one sample: the velocity's process noise.
  double dynamics_accel_std_mps2 = 0.001;
  /// The same model error as the accelerometer's update sees it: the std of
  /// the predicted translational acceleration added to the accelerometer's
  /// noise (m/s^2). Negative: dynamics_accel_std_mps2. Apart because the
  /// legs' corrections need the velocity's process noise while a larger
  /// share here widens d's uncertainty, and so the filter's margin
  /// (docs/estimator.md, "The P-16P legs").
  double accel_update_dynamics_std_mps2 = -1.0;
  double dynamics_angaccel_std_radps2 = 0.01;
  /// Model error d (docs/estimator.md, "Model error"): estimated with the
  /// dynamics model only. A random walk (per sqrt(s)), its initial std, and
  /// the std it is re-opened to when the accelerometer shows a jump; force
  /// rows (N) and Euler-angle rows (N m per rad).
  bool estimate_disturbance = false;
  double disturbance_walk_n_per_sqrt_s = 1.0;
  double disturbance_walk_nm_per_sqrt_s = 0.1;
  double initial_disturbance_std_n = 2.0;
  double initial_disturbance_std_nm = 0.2;
  double disturbance_jump_std_n = 5.0;
  double disturbance_jump_std_nm = 0.5;
  /// Consecutive gated accelerometer samples that make a jump.
  int disturbance_jump_after_samples = 2;
  /// A jump already on the first gated sample when the accelerometer agreed
  /// for at least this many samples before and the innovation gates even
  /// with the command latency allowance's direction freed
  /// (docs/estimator.md, "Steps"). 0: off.
  int disturbance_early_jump_calm_samples = 0;
  /// An early jump that moves d's force rows by more than this (N, norm) is
  /// undone: one sample cannot tell a push from a bad reading, and a step
  /// beyond the largest push the platform is specified for waits for the
  /// next sample. Infinite: no limit.
  double disturbance_early_jump_max_step_n = std::numeric_limits<double>::infinity();
  /// Relative std of what a change of the leg forces changes in d: d holds
  /// (M - M_true) qdd + H diag(gain - 1) F + ..., so an inertia the model
  /// lacks (a payload, its offset) and the legs' force gains move d with
  /// every change of the command, at once, faster than d's walk. Each
  /// predict adds H diag((std dF_i)^2) H^T to d's covariance, dF the change
  /// of the command acting since the previous interval (N). 0: off.
  double disturbance_force_change_std = 0.0;
  /// Largest change of one leg's command (N) the allowance above answers in
  /// full; a larger change counts as this much. The filter's robust margin
  /// grows with d's std, and where the closed form answers a margin with a
  /// large force (both conditions of an axis active, near-parallel normals)
  /// an allowance in proportion to the whole change fed its own command
  /// changes back through the margin (docs/estimator.md, "Force-change
  /// allowance"). Infinite: no cap.
  double disturbance_force_change_cap_n = std::numeric_limits<double>::infinity();
  /// Std (N) of the change of a leg's dry friction when the leg reverses:
  /// at each predict where the estimate's speed of leg i, ld_i = (H^T qd)_i,
  /// changed sign since the previous predict, d's covariance takes
  /// + std^2 h_i h_i^T (h_i: H's column i). The friction's flip is up to
  /// 2 F_c and comes with no change of the command when a leg creeps
  /// through zero speed. 0: off.
  double disturbance_friction_flip_std_n = 0.0;
  /// A leg counts as reversed for the allowance above when its estimated
  /// speed, last beyond this (m/s) one way, is beyond it the other way:
  /// within the band the friction turns over gradually (and the estimate's
  /// noise would flip the sign on every tick at rest).
  double disturbance_friction_flip_speed_mps = 0.0;
  /// Random walk of the gyro bias (rad/s per sqrt(s)).
  double gyro_bias_walk_radps_per_sqrt_s = 1.0e-5;
  /// More walk of the gyro bias while the platform moves, per m/s of
  /// s = |v| + r_P |Euler rates| (r_P the platform joints' largest radius):
  /// the walk is sqrt(walk^2 + (this * s)^2). Joints off the model's tilt
  /// the pose the legs give by an error that changes as the platform moves,
  /// while the gyro reads the true rates; to the EKF the difference is a
  /// gyro bias that changes with the speed. (rad/s per sqrt(s)) per (m/s);
  /// 0: off.
  double gyro_bias_walk_per_speed = 0.0;
  double initial_velocity_std_mps = 0.05;
  double initial_angular_rate_std_radps = 0.2;
  double initial_gyro_bias_std_radps = 0.01;
  /// The accelerometer's bias b_a: its one-sigma uncertainty at a (re)start
  /// (m/s^2; 0: not estimated, held at zero) and its random walk (m/s^2 per
  /// sqrt(s)).
  double initial_accel_bias_std_mps2 = 0.0;
  double accel_bias_walk_mps2_per_sqrt_s = 0.0;
  /// More walk of the accelerometer's bias while the platform moves, per
  /// m/s of the same speed s as gyro_bias_walk_per_speed: the walk is
  /// sqrt(walk^2 + (this * s)^2). The tilt a wrong geometry puts into the
  /// pose changes as the platform moves, and with it the share of gravity
  /// the accelerometer reads against the estimate's attitude.
  /// (m/s^2 per sqrt(s)) per (m/s); 0: off.
  double accel_bias_walk_per_speed = 0.0;
  /// Optional key `accel_bias_axes: xyz | xy` (default xyz): with xy the
  /// bias along {P}'s z is held at zero. The tilt a wrong geometry puts
  /// into the pose shows in x and y; along z a bias shares out a vertical
  /// force deficit with d (docs/estimator.md, "The accelerometer's bias").
  bool estimate_accel_bias_z = true;
  /// Multiplies the leg-length variance (noise + ADC quantisation); > 1
  /// absorbs the time correlation of the quantisation error.
  double leg_noise_inflation = 1.6;
  bool use_accelerometer = true;
  double gating_chi2 = 30.0;  ///< innovation gate, per sensor group and update
  /// Consecutive rejected leg updates after which the filter is diverged and
  /// re-initialised from forward kinematics.
  int divergence_rejections = 50;
  double max_dt_s = 0.05;           ///< larger sample gaps re-initialise
  double command_timeout_s = 0.05;  ///< older commands are not used
  /// Optional key: the actuators act this long after the sample a command
  /// derives from (s): the model applies the command issued that long before
  /// each predicted interval. At most 15 samples (the history kept).
  double command_latency_s = 0.0;
  /// Optional key: the latest the actuators may act after that (s), an
  /// allowance for latency the model does not know. After the drive comes
  /// on, what the samples of this window say of the model error d is
  /// dropped: they may show the legs still held (docs/estimator.md,
  /// "Drive-on"). 0: no window.
  double command_latency_allowance_s = 0.0;
  int settle_samples = 200;          ///< STATUS_INITIALIZING after (re)init
  double max_gyro_radps = 35.0;      ///< larger readings are rejected
  double max_accel_mps2 = 160.0;     ///< larger readings are rejected
  double leg_range_margin_m = 0.01;  ///< accepted beyond the stroke ends
  bool perfect_state = false;        ///< pass ground truth through; testing only
};

}  // namespace stewart
