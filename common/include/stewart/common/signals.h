#pragma once
// The signals the processes pass each other, in library form: what state_t
// and force_command_t carry, without LCM. The nodes convert at the edge
// (node/signal_messages.h, which checks that every bit below equals the
// message's constant); the libraries, replay and the closed loop use these.
//
// Units and frames as in lcmtypes/: q = [x y z (m), phi theta psi (rad,
// Z-Y-X)] of the platform frame {P} in the base frame {B}; qd its time
// derivative; forces along the legs (N). utime in microseconds of stack time.
#include <Eigen/Core>
#include <cstdint>

namespace stewart {

/// A state estimate (or the ground truth): state_t.
struct StateSample {
  int64_t utime = 0;
  int64_t seq = 0;
  int64_t sample_utime = 0;  ///< the sensor sample it derives from
  Eigen::Matrix<double, 6, 1> q = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> qd = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> q_std = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> qd_std = Eigen::Matrix<double, 6, 1>::Zero();
  /// The estimated model error d and its one-sigma uncertainty
  /// (model/disturbance.h; N, N m per rad). Zero for ground truth.
  Eigen::Matrix<double, 6, 1> disturbance = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> disturbance_std = Eigen::Matrix<double, 6, 1>::Zero();
  int32_t status = 0;  ///< kState* bits
};

constexpr int32_t kStateValid = 1;
constexpr int32_t kStateInitializing = 2;
constexpr int32_t kStateDiverged = 4;
constexpr int32_t kStateGroundTruth = 8;
constexpr int32_t kStatePerfectState = 16;

/// The one rule for whether a state estimate may be acted on: valid and not
/// diverged. The controller, the safety filter and replay all ask here.
constexpr bool StateUsable(int32_t status) {
  return (status & kStateValid) != 0 && (status & kStateDiverged) == 0;
}
inline bool StateUsable(const StateSample& state) { return StateUsable(state.status); }

/// A leg force command (nominal or safe): force_command_t.
struct ForceCommand {
  int64_t utime = 0;
  int64_t seq = 0;
  int64_t sample_utime = 0;  ///< the sensor sample it derives from
  Eigen::Matrix<double, 6, 1> force_n = Eigen::Matrix<double, 6, 1>::Zero();
  int32_t flags = 0;  ///< kCommand* bits
  /// Safe commands: the safety session that issued them (0 on nominal ones).
  int64_t session_id = 0;
};

constexpr int32_t kCommandFilterActive = 1;
constexpr int32_t kCommandInfeasible = 2;
constexpr int32_t kCommandFallback = 4;
constexpr int32_t kCommandStaleInput = 8;
constexpr int32_t kCommandInvalidInput = 16;
constexpr int32_t kCommandSetpointRejected = 32;
constexpr int32_t kCommandForceLimited = 64;
/// A limit is exceeded on the state the command was filtered at.
constexpr int32_t kCommandOutsideSafeSet = 128;
/// Actuators off, the lead screws hold the legs (supervisor DISARMED or
/// ESTOP); force_n is zero.
constexpr int32_t kCommandDriveOff = 256;
/// The nominal asked for more acceleration than one sample period allows;
/// the filter solved its conditions for the scaled nominal.
constexpr int32_t kCommandNominalBounded = 512;
/// The composed filter's answer broke one barrier's own condition; the
/// un-composed QP answered instead.
constexpr int32_t kCommandPerBarrier = 1024;

}  // namespace stewart
