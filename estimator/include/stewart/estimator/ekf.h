#pragma once
// Extended Kalman filter fusing the leg potentiometers and the IMU into the
// platform state [q, qd], the model error d and the gyro and accelerometer
// biases. docs/estimator.md describes the
// model, the tuning and the measured accuracy. No LCM, no heap allocation
// per update, and time only from the samples' utime.
#include <array>
#include <memory>
#include <optional>

#include "stewart/estimator/ekf_types.h"
#include "stewart/estimator/estimator_config.h"
#include "stewart/model/actuator_params.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/rotation.h"
#include "stewart/model/sensor_params.h"
#include "stewart/model/shared_dynamics_terms.h"

namespace stewart {

class Ekf {
 public:
  Ekf(const PlatformParams& params, const ActuatorConfig& actuators, const SensorConfig& sensors,
      const EstimatorConfig& config, const Vector6d& home_pose);

  /// The leg forces being applied (N) from command sample time `utime` (us):
  /// the process model's input.
  /// `drive_off`: the command turned the drive off (force_command_t
  /// FLAG_DRIVE_OFF): the lead screws hold the legs, whatever the actuator.
  void SetForceCommand(int64_t utime, const Vector6d& force_n, bool drive_off = false);

  /// One predict + correct step per sensor sample. Before the first valid leg
  /// reading it initialises from forward kinematics.
  UpdateResult Update(const SensorSample& sample);

  /// Starts from a given state with one-sigma uncertainty `std` (tests and
  /// tools; the process initialises itself from the legs).
  void Initialize(int64_t utime, const Vector6d& q, const Vector6d& qd, const EkfVector& std);
  void Reset();

  /// Evaluates the model through `shared` (in process: the controller and
  /// the filter evaluate it at the estimate this filter publishes, which the
  /// next prediction starts from). std::invalid_argument when its parameters
  /// are not this filter's; null: evaluations of its own.
  void ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared);

  bool initialized() const { return initialized_; }
  const EkfVector& x() const { return x_; }
  EkfMatrix P() const { return P_.topLeftCorner<kEkfStateSize, kEkfStateSize>(); }
  Estimate estimate() const;
  /// Normalised innovation squared of the last leg update (chi-square, 6 dof).
  double last_leg_nis() const { return last_leg_nis_; }
  /// qdd used by the last prediction.
  const Vector6d& predicted_qdd() const { return qdd_; }

 private:
  bool InitializeFromLegs(const SensorSample& sample, uint32_t* events);
  // `trig`: sines and cosines of the current estimate's Euler angles.
  /// `drive_off`: the sample says no drive acted over the interval.
  void Predict(double dt_s, int64_t utime, const EulerAngleTrig& trig, bool drive_off,
               uint32_t* events);
  void CorrectLegs(const Vector6d& leg_length_m, const EulerAngleTrig& trig, uint32_t* events);
  void CorrectGyro(const Vector3d& gyro_radps, const EulerAngleTrig& trig, uint32_t* events);
  void CorrectAccel(const Vector3d& accel_mps2, const EulerAngleTrig& trig, uint32_t* events);
  void CorrectOrientation(const Vector3d& rpy_rad, uint32_t* events);
  /// Kalman correction with innovation `y` for a measurement whose Jacobian
  /// is non-zero only in the 3-column state blocks starting at `blocks`
  /// (`h` holds those blocks side by side); false (and no change) when the
  /// innovation fails the gate. With `gate_only` the state is never changed:
  /// only whether the innovation passes the gate.
  template <int M, int NB>
  bool Correct(const Eigen::Matrix<double, M, 1>& y, const std::array<int, NB>& blocks,
               const Eigen::Matrix<double, M, 3 * NB>& h, const Eigen::Matrix<double, M, M>& R,
               double* nis, bool gate_only = false);
  bool LegsUsable(const SensorSample& sample, uint32_t* events) const;
  bool EstimatesAccelBias() const { return config_.initial_accel_bias_std_mps2 > 0.0; }

  PlatformParams params_;
  std::shared_ptr<SharedDynamicsTerms> shared_terms_;
  ActuatorConfig actuators_;
  double leg_damping_nspm_;  // N s/m: screw friction + back-EMF (ModelLegDampingNspm)
  // s: how fast held DC-motor legs stop, reflected mass / back-EMF damping
  // (at least 2 ms: a massless rotor stops within a sample or two).
  double hold_time_constant_s_;
  EstimatorConfig config_;
  Vector6d home_pose_;
  Vector3d imu_offset_m_;
  double leg_variance_m2_;
  double platform_joint_radius_m_;  // the largest; for the gyro bias's speed walk
  double gyro_variance_;
  double accel_variance_;
  double orientation_variance_;

  bool initialized_ = false;
  int64_t last_utime_ = 0;
  EkfVector x_ = EkfVector::Zero();
  /// P in a kEkfPaddedSize square matrix whose padding rows and columns are
  /// zero: every column is a whole number of SIMD packets.
  using PaddedMatrix = Eigen::Matrix<double, kEkfPaddedSize, kEkfPaddedSize>;
  PaddedMatrix P_ = PaddedIdentity();
  static PaddedMatrix PaddedIdentity();
  Vector6d qdd_ = Vector6d::Zero();
  bool qdd_from_dynamics_ = false;
  Matrix6d dqdd_dq_ = Matrix6d::Zero();  ///< dynamics model, at the last predict
  Matrix6d dqdd_dqd_ = Matrix6d::Zero();
  Matrix6d m_inv_ = Matrix6d::Zero();  ///< dqdd/dd = M^-1, at the last predict
  /// The latest commands (sample utime, force), newest at
  /// command_history_[(command_next_ - 1) % kCommandHistory]: the model
  /// applies the one issued command_latency_s before each interval.
  struct TimedCommand {
    int64_t utime = 0;
    Vector6d force_n = Vector6d::Zero();
    bool drive_off = false;  ///< the supervisor turned the drive off: legs held
  };
  static constexpr int kCommandHistory = 16;
  std::array<TimedCommand, kCommandHistory> command_history_{};
  int command_next_ = 0;
  int command_count_ = 0;
  /// The command acting from `interval_start_utime` on, or nullptr.
  const TimedCommand* ActingCommand(int64_t interval_start_utime) const;
  int consecutive_leg_rejections_ = 0;
  int consecutive_accel_gated_ = 0;
  int consecutive_gyro_gated_ = 0;
  /// See CorrectGyro: the gyro gated this many samples in a row first (a
  /// single bad reading is only gated).
  static constexpr int kReopenAfterGatedGyro = 3;
  /// See ReopenPoseAfterUnmodelledForce: the legs gated this many samples
  /// in a row first (a single bad reading is only gated), and the longest
  /// window the drift is sized for (s).
  static constexpr int kReopenAfterGatedLegs = 3;
  static constexpr double kMaxReopenWindowS = 0.05;
  static constexpr int kNeverDisagreed = 1 << 30;
  /// Widens the pose and velocity uncertainty by the drift of an unmodelled
  /// force, when the legs and the accelerometer both disagree; true if done.
  bool ReopenPoseAfterUnmodelledForce();
  static constexpr double kMinReopenIntervalS = 0.5;
  std::optional<int64_t> pose_reopened_utime_;           ///< the latest re-opening
  int samples_since_accel_disagreed_ = kNeverDisagreed;  ///< gated or jumped
  /// See CorrectAccel (disturbance_early_jump_calm_samples): the latency
  /// allowance's term in the accelerometer's noise scaled by this (1000x its
  /// std) frees the innovation along the direction a late command moves the
  /// specific force, and nothing else.
  static constexpr double kLatencyDirectionFreed = 1.0e6;
  int64_t accel_disagreement_start_utime_ = 0;  ///< first sample of the latest disagreement
  int samples_since_init_ = 0;
  /// The drive coming on (see Predict): d and its covariance as they were
  /// before, restored after every sample until command_latency_allowance_s
  /// has passed.
  bool legs_were_held_ = false;
  bool drive_on_window_ = false;
  int64_t drive_on_command_utime_ = 0;
  Vector6d d_before_drive_on_ = Vector6d::Zero();
  Matrix6d p_dd_before_drive_on_ = Matrix6d::Zero();
  void RestoreDisturbanceBeforeDriveOn();
  /// See Predict: the acceleration the model's command may be off by over
  /// the latest interval, from the command latency allowance (1/s^2 per axis).
  Vector6d latency_accel_ = Vector6d::Zero();
  Matrix6d dqdd_dforce_ = Matrix6d::Zero();
  /// See Predict (disturbance_force_change_std): H at the last predict, and
  /// the force the model applied over the previous interval (absent when
  /// the legs were held or no command acted).
  Matrix6d h_ = Matrix6d::Zero();
  std::optional<Vector6d> previous_model_force_n_;
  /// See Predict (disturbance_friction_flip_std_n): each leg's direction
  /// (+1 lengthening, -1 shortening, 0 not yet known) when its estimated
  /// speed ld = H^T qd was last beyond disturbance_friction_flip_speed_mps
  /// (absent when the model did not act or after a restart).
  std::optional<Vector6d> previous_leg_direction_;
  /// The largest such error among the commands that may act instead of the
  /// model's `command` over the interval starting at `interval_start_utime`.
  Vector6d LatencyAccelerationError(const TimedCommand& command, int64_t interval_start_utime,
                                    const Vector6d& qd) const;
  bool diverged_ = false;
  double last_leg_nis_ = 0.0;
};

}  // namespace stewart
