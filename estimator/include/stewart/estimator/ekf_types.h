#pragma once
// Fixed-size types of the estimator: the EKF state layout, one sensor sample,
// the estimate, and the events an update can report.
#include <cstdint>

#include "stewart/model/types.h"

namespace stewart {

/// EKF state x = [q (6), qd (6), d (6), b_g (3), b_a (3)]: pose (m, rad;
/// Z-Y-X Euler), its time derivative (m/s, rad/s Euler rates), the model
/// error d of M qdd + C qd + G = H F + d (N, N m per rad;
/// model/disturbance.h), gyro bias (rad/s, {P} axes), accelerometer bias
/// (m/s^2, {P} axes: added to the specific force it reads).
constexpr int kEkfStateSize = 24;
constexpr int kEkfQ = 0;
constexpr int kEkfQd = 6;
constexpr int kEkfDisturbance = 12;
constexpr int kEkfGyroBias = 18;
constexpr int kEkfAccelBias = 21;
/// P's storage: the state size rounded up to whole SIMD packets (2 doubles),
/// the padding rows and columns zero.
constexpr int kEkfPaddedSize = (kEkfStateSize + 1) / 2 * 2;
using EkfVector = Eigen::Matrix<double, kEkfStateSize, 1>;
using EkfMatrix = Eigen::Matrix<double, kEkfStateSize, kEkfStateSize>;

/// One sensor sample, as the library sees it (no LCM types here).
struct SensorSample {
  int64_t utime = 0;  ///< sample time (us): the only clock of the filter
  int64_t seq = 0;    ///< the sample's number (a resend repeats utime and seq)
  Vector6d leg_length_m = Vector6d::Zero();
  Vector3d gyro_radps = Vector3d::Zero();  ///< {P} axes
  Vector3d accel_mps2 = Vector3d::Zero();  ///< specific force, {P} axes
  Vector3d orientation_rpy_rad = Vector3d::Zero();
  bool legs_valid = true;  ///< false when the device flags a leg fault
  bool imu_valid = true;   ///< false when the device flags an IMU fault
  bool has_orientation = false;
  /// The source applied the answer to its previous sample over the interval
  /// ending here (sensor_t::STATUS_ANSWER_APPLIED; lockstep plant_sim).
  bool previous_answer_applied = false;
  /// No drive over the interval ending here: the actuators off or the
  /// device's watchdog (sensor_t::STATUS_ACTUATORS_OFF, STATUS_DEVICE_WATCHDOG),
  /// whatever the safe commands said; the lead screws hold the legs.
  bool drive_off = false;
};

/// The filter's output for one sample.
struct Estimate {
  int64_t utime = 0;  ///< = utime of the sensor sample
  Vector6d q = Vector6d::Zero();
  Vector6d qd = Vector6d::Zero();
  Vector6d q_std = Vector6d::Zero();
  Vector6d qd_std = Vector6d::Zero();
  Vector3d gyro_bias_radps = Vector3d::Zero();
  Vector3d accel_bias_mps2 = Vector3d::Zero();    ///< b_a, {P} axes
  Vector6d disturbance_n = Vector6d::Zero();      ///< d (N, N m per rad)
  Vector6d disturbance_std_n = Vector6d::Zero();  ///< its one-sigma uncertainty
  bool initializing = false;                      ///< within settle_samples of a (re)initialisation
  bool diverged = false;  ///< a divergence was detected and the filter restarted
};

/// Events of one update, as a bit set. Rejections are bad or inconsistent
/// inputs that were not used; the others are informational.
enum EkfEvent : uint32_t {
  kEventInitialized = 1u << 0,    ///< (re)initialised from forward kinematics
  kEventReinitTimeGap = 1u << 1,  ///< dt > max_dt_s: restarted
  kEventDiverged = 1u << 2,       ///< divergence detected: restarted
  kEventNoCommand = 1u << 3,      ///< dynamics model had no fresh command
  kRejectTime = 1u << 4,          ///< dt <= 0: the whole sample is ignored
  kRejectLegsNonFinite = 1u << 5,
  kRejectLegsRange = 1u << 6,
  kRejectGyroInvalid = 1u << 7,  ///< non-finite or out of range
  kRejectAccelInvalid = 1u << 8,
  kRejectOrientationInvalid = 1u << 9,
  kGateLegs = 1u << 10,  ///< innovation outside the chi-square gate
  kGateGyro = 1u << 11,
  kGateAccel = 1u << 12,
  kGateOrientation = 1u << 13,
  kRejectInitFailed = 1u << 14,  ///< forward kinematics did not converge
  /// The accelerometer disagreed with the predicted acceleration beyond its
  /// gate: d's uncertainty was re-opened (a push, a payload change) and the
  /// sample used again.
  kEventDisturbanceJump = 1u << 15,
  /// DC-motor legs without drive (no fresh command, or an all-zero one):
  /// predicted as held by their self-locking screws, not by the dynamics.
  kEventLegsHeld = 1u << 16,
  /// Legs gated 3 samples in a row while the accelerometer disagreed too:
  /// the pose and velocity uncertainty widened by the drift of an unmodelled
  /// force, and the legs used (Ekf::ReopenPoseAfterUnmodelledForce).
  kEventPoseReopened = 1u << 17,
  /// The gyro gated 3 samples in a row: the angular rates' uncertainty
  /// widened by the disagreement, and the gyro used (Ekf::CorrectGyro).
  kEventRatesReopened = 1u << 18,
  kEventLast = kEventRatesReopened,
};

/// Short snake_case name of one event bit (health counter names).
const char* EkfEventName(EkfEvent event);
/// True for the bits that are rejected inputs.
bool IsRejection(EkfEvent event);

struct UpdateResult {
  uint32_t events = 0;
  bool has_estimate = false;  ///< false: nothing to publish for this sample
  bool Has(EkfEvent e) const { return (events & e) != 0; }
};

}  // namespace stewart
