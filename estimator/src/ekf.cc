#include "stewart/estimator/ekf.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <utility>

#include "stewart/estimator/measurement_models.h"
#include "stewart/estimator/process_model.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

constexpr double kUsToS = 1e-6;
// An estimate this uncertain is no estimate: restart instead of publishing it.
constexpr double kMaxPositionStdM = 0.05;
// A learnt d beyond this many of its largest configured stds is taken as the
// arithmetic's breakdown and not kept through a restart.
constexpr double kKeptDisturbanceSigmas = 10.0;

double HoldTimeConstant(const ActuatorConfig& actuators) {
  // Ideal-force legs are held only when the supervisor turns the drive off:
  // the lead screws stop them within a few samples.
  constexpr double kMinHoldTimeConstantS = 2e-3;
  if (actuators.kind != ActuatorKind::kDcMotor) return kMinHoldTimeConstantS;
  return std::max(actuators.motor.reflected_mass_kg / ModelLegDampingNspm(actuators),
                  kMinHoldTimeConstantS);
}

// The dynamics model's acceleration std in the accelerometer's update (m/s^2).
double AccelUpdateDynamicsStd(const EstimatorConfig& config) {
  return config.accel_update_dynamics_std_mps2 > 0.0 ? config.accel_update_dynamics_std_mps2
                                                     : config.dynamics_accel_std_mps2;
}

// Discrete white-noise acceleration (one sample of constant acceleration with
// std sigma) on the (q_i, qd_i) pair of axis i.
template <typename Matrix>
void AddWhiteAcceleration(int axis, double sigma, double dt_s, Matrix* P) {
  const double v = sigma * sigma;
  const double dt2 = dt_s * dt_s;
  (*P)(kEkfQ + axis, kEkfQ + axis) += v * 0.25 * dt2 * dt2;
  (*P)(kEkfQ + axis, kEkfQd + axis) += v * 0.5 * dt2 * dt_s;
  (*P)(kEkfQd + axis, kEkfQ + axis) += v * 0.5 * dt2 * dt_s;
  (*P)(kEkfQd + axis, kEkfQd + axis) += v * dt2;
}

// S = L D L^T of a small symmetric positive definite matrix (only its lower
// triangle is read). Compute is false unless every pivot is positive and
// finite: S not positive definite, or NaN in it.
template <int N>
struct LdltSmall {
  Eigen::Matrix<double, N, N> l;  // strictly lower triangle: L (unit diagonal)
  Eigen::Matrix<double, N, 1> inv_d;
  bool Compute(const Eigen::Matrix<double, N, N>& s) {
    Eigen::Matrix<double, N, 1> d;
    for (int j = 0; j < N; ++j) {
      double djj = s(j, j);
      for (int k = 0; k < j; ++k) djj -= l(j, k) * l(j, k) * d(k);
      if (!(djj > 0.0 && djj < HUGE_VAL)) return false;
      d(j) = djj;
      inv_d(j) = 1.0 / djj;
      for (int i = j + 1; i < N; ++i) {
        double lij = s(i, j);
        for (int k = 0; k < j; ++k) lij -= l(i, k) * l(j, k) * d(k);
        l(i, j) = lij * inv_d(j);
      }
    }
    return true;
  }
};

// Whether every entry is finite: x - x is 0 for a finite x and NaN otherwise,
// and a sum with a NaN in it is NaN (one vectorised pass, no branch per entry).
template <typename Derived>
bool AllFinite(const Eigen::MatrixBase<Derived>& m) {
  return (m.array() - m.array()).sum() == 0.0;
}

// sin and cos of `to` = from + delta from those of `from`, by the angle-sum
// formulas with sin and cos of delta from their Taylor series (for
// |delta| <= 0.01 the first omitted terms, delta^9/9! and delta^10/10!, are
// below 1e-23; measured over 1e7 random steps, the results differ from
// std::sin and std::cos by at most 4 ulp of max(|sin from|, |sin to|) and 2 ulp
// of cos); a direct evaluation for larger steps.
EulerAngleTrig ShiftEulerAngleTrig(const EulerAngleTrig& from, const Vector3d& delta,
                                   const Vector3d& to) {
  if (!(delta.cwiseAbs().maxCoeff() <= 0.01)) return EulerAngleTrig(to);
  const auto shift = [](double d, double* s, double* c) {
    const double d2 = d * d;
    const double sd = d + d * d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040)));
    const double cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320))));
    const double s0 = *s, c0 = *c;
    *s = s0 * cd + c0 * sd;
    *c = c0 * cd - s0 * sd;
  };
  EulerAngleTrig t = from;
  shift(delta.x(), &t.sin_phi, &t.cos_phi);
  shift(delta.y(), &t.sin_theta, &t.cos_theta);
  shift(delta.z(), &t.sin_psi, &t.cos_psi);
  return t;
}

// P -= G G^T on the lower block triangle (blocks of rows and columns [0, 6),
// [6, 12), [12, 18), [18, 24)), the upper blocks as the mirror. Inside a
// diagonal block an entry and its mirror are the same sum of the same
// products in the same order, so P stays symmetric to the last bit.
template <int Start, int End, int M>
void SubtractGramBlock(const Eigen::Matrix<double, kEkfPaddedSize, M>& g,
                       Eigen::Matrix<double, kEkfPaddedSize, kEkfPaddedSize>* p) {
  // Rows from the 4-aligned row at or above the block (whole, aligned AVX
  // packets; 18 or 6 rows from row 6 or 18 would be 2-wide): the extra rows
  // lie in the upper block above, which the mirror overwrites.
  constexpr int kFirst = Start / 4 * 4;
  constexpr int kRows = kEkfPaddedSize - kFirst;
  for (int j = Start; j < End; ++j) {
    Eigen::Matrix<double, kRows, 1> col = p->col(j).template tail<kRows>();
    for (int k = 0; k < M; ++k) col -= g(j, k) * g.col(k).template tail<kRows>();
    p->col(j).template tail<kRows>() = col;
  }
}

// The upper off-diagonal 6x6 blocks := the mirror of the lower ones.
template <int N>
void MirrorOffDiagonalBlocks(Eigen::Matrix<double, N, N>* p) {
  static_assert(N == 24, "four blocks of 6");
  p->template block<6, N - 6>(0, 6) = p->template block<N - 6, 6>(6, 0).transpose();
  p->template block<6, N - 12>(6, 12) = p->template block<N - 12, 6>(12, 6).transpose();
  p->template block<6, N - 18>(12, 18) = p->template block<N - 18, 6>(18, 12).transpose();
}

// Upper triangle := lower triangle, by 6x6 blocks with fixed bounds (fully
// unrolled; the triangular double loop with variable bounds over 276 entries
// was a fifth of the prediction).
template <int N>
void MirrorLowerTriangle(Eigen::Matrix<double, N, N>* p) {
  for (int b = 0; b < N; b += 6) {
#pragma GCC unroll 6
    for (int j = 1; j < 6; ++j) {
#pragma GCC unroll 6
      for (int i = 0; i < j; ++i) (*p)(b + i, b + j) = (*p)(b + j, b + i);
    }
  }
  MirrorOffDiagonalBlocks(p);
}

template <int M>
void SubtractGram(const Eigen::Matrix<double, kEkfPaddedSize, M>& g,
                  Eigen::Matrix<double, kEkfPaddedSize, kEkfPaddedSize>* p) {
  static_assert(kEkfQd == 6 && kEkfDisturbance == 12 && kEkfGyroBias == 18 && kEkfAccelBias == 21 &&
                    kEkfPaddedSize == 24,
                "the blocks below follow the state layout");
  SubtractGramBlock<0, 6>(g, p);
  SubtractGramBlock<6, 12>(g, p);
  SubtractGramBlock<12, 18>(g, p);
  SubtractGramBlock<18, kEkfStateSize>(g, p);
  MirrorOffDiagonalBlocks(p);
}

}  // namespace

Ekf::Ekf(const PlatformParams& params, const ActuatorConfig& actuators, const SensorConfig& sensors,
         const EstimatorConfig& config, const Vector6d& home_pose)
    : params_(params),
      actuators_(actuators),
      leg_damping_nspm_(ModelLegDampingNspm(actuators)),
      hold_time_constant_s_(HoldTimeConstant(actuators)),
      config_(config),
      home_pose_(home_pose),
      imu_offset_m_(sensors.imu_offset_in_P_m) {
  const double step = LegAdcStepM(sensors, actuators.stroke_m);
  // The quantisation error is uniform over one ADC step: variance step^2/12.
  leg_variance_m2_ =
      config.leg_noise_inflation *
      (sensors.leg_pot_noise_std_m * sensors.leg_pot_noise_std_m + step * step / 12.0);
  // A floor keeps S invertible for ideal (noise-free) sensor configs.
  leg_variance_m2_ = std::max(leg_variance_m2_, 1e-14);
  platform_joint_radius_m_ = params.platform_joints_in_P_m.colwise().norm().maxCoeff();
  gyro_variance_ = std::max(sensors.gyro_noise_std_radps * sensors.gyro_noise_std_radps, 1e-14);
  accel_variance_ = std::max(sensors.accel_noise_std_mps2 * sensors.accel_noise_std_mps2, 1e-14);
  orientation_variance_ =
      std::max(sensors.orientation_noise_std_rad * sensors.orientation_noise_std_rad, 1e-14);
}

void Ekf::SetForceCommand(int64_t utime, const Vector6d& force_n, bool drive_off) {
  if (!force_n.allFinite()) return;  // the node counts it; never feed NaN into the model
  TimedCommand& slot = command_history_[static_cast<size_t>(command_next_)];
  slot.utime = utime;
  slot.force_n = force_n.cwiseMax(-actuators_.force_limit_n).cwiseMin(actuators_.force_limit_n);
  slot.drive_off = drive_off;
  command_next_ = (command_next_ + 1) % kCommandHistory;
  command_count_ = std::min(command_count_ + 1, kCommandHistory);
}

const Ekf::TimedCommand* Ekf::ActingCommand(int64_t interval_start_utime) const {
  // The newest command issued at least the latency before the interval
  // starts; without a latency, the newest command.
  const int64_t latest_utime =
      interval_start_utime - static_cast<int64_t>(config_.command_latency_s / kUsToS);
  for (int k = 0; k < command_count_; ++k) {
    const TimedCommand& c = command_history_[static_cast<size_t>(
        (command_next_ - 1 - k + kCommandHistory) % kCommandHistory)];
    if (config_.command_latency_s <= 0.0 || c.utime <= latest_utime) return &c;
  }
  return nullptr;
}

void Ekf::ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared) {
  shared_terms_ = AttachSharedTerms(params_, std::move(shared));
}

void Ekf::Reset() {
  initialized_ = false;
  x_.setZero();
  P_ = PaddedIdentity();
  qdd_.setZero();
  consecutive_leg_rejections_ = 0;
  consecutive_accel_gated_ = 0;
  consecutive_gyro_gated_ = 0;
  pose_reopened_utime_.reset();
  samples_since_accel_disagreed_ = kNeverDisagreed;
  samples_since_init_ = 0;
  drive_on_window_ = false;         // a restart keeps its own d
  previous_leg_direction_.reset();  // a restart's velocity is a new estimate
}

void Ekf::Initialize(int64_t utime, const Vector6d& q, const Vector6d& qd, const EkfVector& std) {
  x_.segment<6>(kEkfQ) = q;
  x_.segment<6>(kEkfQd) = qd;
  x_.segment<6>(kEkfDisturbance).setZero();
  x_.segment<3>(kEkfGyroBias).setZero();
  x_.segment<3>(kEkfAccelBias).setZero();
  P_.setZero();
  P_.diagonal().head<kEkfStateSize>() = std.cwiseProduct(std);
  // Without disturbance estimation d is held at zero, with zero covariance;
  // so is the accelerometer's bias when it is not estimated.
  if (!config_.estimate_disturbance) P_.diagonal().segment<6>(kEkfDisturbance).setZero();
  if (!EstimatesAccelBias()) P_.diagonal().segment<3>(kEkfAccelBias).setZero();
  qdd_.setZero();
  last_utime_ = utime;
  initialized_ = true;
  consecutive_leg_rejections_ = 0;
  consecutive_accel_gated_ = 0;
  consecutive_gyro_gated_ = 0;
  pose_reopened_utime_.reset();
  samples_since_accel_disagreed_ = kNeverDisagreed;
  samples_since_init_ = 0;
  drive_on_window_ = false;         // a restart keeps its own d
  previous_leg_direction_.reset();  // a restart's velocity is a new estimate
}

bool Ekf::LegsUsable(const SensorSample& sample, uint32_t* events) const {
  if (!sample.legs_valid) return false;
  if (!sample.leg_length_m.allFinite()) {
    *events |= kRejectLegsNonFinite;
    return false;
  }
  const double lo = params_.leg_min_length_m - config_.leg_range_margin_m;
  const double hi = params_.leg_max_length_m + config_.leg_range_margin_m;
  if ((sample.leg_length_m.array() < lo).any() || (sample.leg_length_m.array() > hi).any()) {
    *events |= kRejectLegsRange;
    return false;
  }
  return true;
}

bool Ekf::InitializeFromLegs(const SensorSample& sample, uint32_t* events) {
  const Vector6d guess = initialized_ ? Vector6d(x_.segment<6>(kEkfQ)) : home_pose_;
  ForwardKinematicsResult fk = ForwardKinematics(params_, sample.leg_length_m, guess);
  if (!fk.converged && initialized_)
    fk = ForwardKinematics(params_, sample.leg_length_m, home_pose_);
  if (!fk.converged || !fk.q.allFinite()) {
    *events |= kRejectInitFailed;
    return false;
  }
  // One leg reading fixes the pose to about its noise (a few legs' worth);
  // the velocity and the gyro bias are unknown.
  EkfVector std;
  std.segment<6>(kEkfQ).setConstant(10.0 * std::sqrt(leg_variance_m2_));
  std.segment<3>(kEkfQd).setConstant(config_.initial_velocity_std_mps);
  std.segment<3>(kEkfQd + 3).setConstant(config_.initial_angular_rate_std_radps);
  std.segment<3>(kEkfGyroBias).setConstant(config_.initial_gyro_bias_std_radps);
  std.segment<3>(kEkfAccelBias).setConstant(config_.initial_accel_bias_std_mps2);
  if (!config_.estimate_accel_bias_z) std(kEkfAccelBias + 2) = 0.0;
  std.segment<3>(kEkfDisturbance).setConstant(config_.initial_disturbance_std_n);
  std.segment<3>(kEkfDisturbance + 3).setConstant(config_.initial_disturbance_std_nm);
  // A restart keeps what was learnt of d (a payload does not go away when
  // the estimate is restarted), with its initial uncertainty.
  const Vector6d d_before = x_.segment<6>(kEkfDisturbance);
  // ... unless the restart is the arithmetic's breakdown (a d far beyond any
  // uncertainty the config allows for is that). The bound takes the larger of
  // the jump and the initial std per row: `jump_std_nm: 0` (no jumps on the
  // rotation rows) made it 0 N m, and every restart dropped a learnt d: the
  // next return of the drive repeated the error just learnt (bounds
  // campaign, 40 runs: 1622 -> 835 restarts with this alone, docs/campaign.md).
  const double bound_n = kKeptDisturbanceSigmas * std::max(config_.disturbance_jump_std_n,
                                                           config_.initial_disturbance_std_n);
  const double bound_nm = kKeptDisturbanceSigmas * std::max(config_.disturbance_jump_std_nm,
                                                            config_.initial_disturbance_std_nm);
  const bool keep_d = initialized_ && AllFinite(d_before) &&
                      (d_before.head<3>().array().abs() <= bound_n).all() &&
                      (d_before.tail<3>().array().abs() <= bound_nm).all();
  Initialize(sample.utime, fk.q, Vector6d::Zero(), std);
  if (keep_d && config_.estimate_disturbance) x_.segment<6>(kEkfDisturbance) = d_before;
  *events |= kEventInitialized;
  return true;
}

void Ekf::Predict(double dt_s, int64_t utime, const EulerAngleTrig& trig, bool drive_off,
                  uint32_t* events) {
  const Vector6d q = x_.segment<6>(kEkfQ);
  const Vector6d qd = x_.segment<6>(kEkfQd);
  const TimedCommand* command = ActingCommand(last_utime_);
  const bool command_fresh =
      command != nullptr &&
      utime - command->utime <= static_cast<int64_t>(config_.command_timeout_s / kUsToS);
  const bool dynamics_model = config_.process_model == EstimatorProcessModel::kDynamics;
  // DC-motor legs without drive (before the first command, after the drive
  // timed out, or a zero command: the safe stop) are held by their
  // self-locking screws, which the dynamics model does not know: with F = 0
  // it would predict the platform sinking against the legs' damping and
  // explain the legs' stillness as model error d, which the controller and
  // the filter then apply as soon as the drive returns.
  // Any legs with the drive turned off by the supervisor (DISARMED, ESTOP),
  // or by the actuators themselves (the plant's command timeout or guard,
  // the device's watchdog: the sample says so), are held likewise. Without
  // the sample's word the safe commands the actuators refused were predicted
  // and d absorbed the stillness; when the drive returned, d's compensation
  // pushed a held platform to 0.10 m/s in 8 ms (docs/operations.md,
  // "Several hosts").
  const bool legs_held = dynamics_model && (drive_off || (command_fresh && command->drive_off) ||
                                            (actuators_.kind == ActuatorKind::kDcMotor &&
                                             (!command_fresh || command->force_n.isZero())));
  const bool use_dynamics = dynamics_model && command_fresh && !legs_held;
  if (use_dynamics && legs_were_held_ && config_.estimate_disturbance &&
      config_.command_latency_allowance_s > 0.0) {
    // The drive comes on. Until the latency allowance has passed, a sample
    // may show the legs still held: a platform at rest whatever d is, which
    // the model would read as d = what balances the command. Pinned within
    // one sample, such a d held a 0.28 N m payload torque gated for 100 ms,
    // and the estimate restarted. What those samples say of d is dropped
    // after each of them: the commands of the window hold with the d of
    // before, and d is learnt from samples the drive surely acted on.
    drive_on_window_ = true;
    drive_on_command_utime_ = command->utime;
    d_before_drive_on_ = x_.segment<6>(kEkfDisturbance);
    p_dd_before_drive_on_ = P_.block<6, 6>(kEkfDisturbance, kEkfDisturbance);
  } else if (!use_dynamics ||
             (drive_on_window_ && last_utime_ - drive_on_command_utime_ >=
                                      static_cast<int64_t>(std::llround(
                                          config_.command_latency_allowance_s / kUsToS)))) {
    drive_on_window_ = false;
  }
  legs_were_held_ = legs_held;
  double sigma_lin = config_.process_accel_std_mps2;
  double sigma_ang = config_.process_angaccel_std_radps2;
  const bool force_change_allowed =
      use_dynamics && config_.estimate_disturbance && config_.disturbance_force_change_std > 0.0;
  const bool friction_flip_allowed =
      use_dynamics && config_.estimate_disturbance && config_.disturbance_friction_flip_std_n > 0.0;
  if (use_dynamics) {
    const bool latency_allowed = config_.command_latency_allowance_s > 0.0;
    DynamicsAccelerationJacobians(params_, leg_damping_nspm_, q, trig, qd, command->force_n,
                                  x_.segment<6>(kEkfDisturbance), &qdd_, &dqdd_dq_, &dqdd_dqd_,
                                  &m_inv_, shared_terms_.get(),
                                  latency_allowed ? &dqdd_dforce_ : nullptr,
                                  force_change_allowed || friction_flip_allowed ? &h_ : nullptr);
    latency_accel_ =
        latency_allowed ? LatencyAccelerationError(*command, last_utime_, qd) : Vector6d::Zero();
    sigma_lin = config_.dynamics_accel_std_mps2;
    sigma_ang = config_.dynamics_angaccel_std_radps2;
  } else if (legs_held) {
    latency_accel_.setZero();
    // Held: the motion dies out with the legs' time constant; d takes no part.
    *events |= kEventLegsHeld;
    qdd_ = -qd / hold_time_constant_s_;
    dqdd_dq_.setZero();
    dqdd_dqd_ = Matrix6d::Identity() * (-1.0 / hold_time_constant_s_);
    m_inv_.setZero();
    sigma_lin = config_.dynamics_accel_std_mps2;
    sigma_ang = config_.dynamics_angaccel_std_radps2;
  } else {
    latency_accel_.setZero();
    if (config_.process_model == EstimatorProcessModel::kDynamics) *events |= kEventNoCommand;
    qdd_.setZero();
  }
  qdd_from_dynamics_ = use_dynamics;
  x_.segment<6>(kEkfQ) += dt_s * qd + 0.5 * dt_s * dt_s * qdd_;
  x_.segment<6>(kEkfQd) += dt_s * qdd_;

  // P <- Phi P Phi^T with the transition of [q; qd; d] to first order in dt,
  //   Phi = [[I, dt I, 0], [0, I, 0], [0, 0, I]] + [[0, 0, 0], [W], [0, 0, 0]],
  //   W = dt [A, B, M^-1]
  // (A = dqdd/dq, B = dqdd/dqd, M^-1 = dqdd/dd; W = 0 for the
  // constant-velocity model), and the identity on d and the gyro bias, in
  // place: first T = Phi P (rows), then T Phi^T (columns). With
  // U = W P_[(q,qd,d), :] (6x24):
  //   T_q = P_q + dt P_v,  T_v = P_v + U                  (rows)
  //   P'_:q = T_:q + dt T_:v                               (columns)
  //   P'_vv = T_vv + T_v,(q,qd,d) W^T,  P'_(d,b)v = P_(d,b)v + U_(d,b)^T
  // and the upper blocks as the mirror of the lower ones.
  const auto rows_v = P_.middleRows<6>(kEkfQd);
  if (use_dynamics || legs_held) {
    Eigen::Matrix<double, 6, 18> w;
    w << dt_s * dqdd_dq_, dt_s * dqdd_dqd_, dt_s * m_inv_;
    // U^T = P_[:, (q,qd,d)] W^T (P is symmetric to the last bit): column i
    // is a sum of whole columns of P, 24 entries each, which vectorises;
    // the row form's 18-term dot products did not (16 % of the update).
    Eigen::Matrix<double, kEkfPaddedSize, 6> u_t;
    for (int i = 0; i < 6; ++i) {
      Eigen::Matrix<double, kEkfPaddedSize, 1> col = w(i, 0) * P_.col(0);
      for (int k = 1; k < 18; ++k) col += w(i, k) * P_.col(k);
      u_t.col(i) = col;
    }
    P_.middleRows<6>(kEkfQ) += dt_s * rows_v;
    P_.middleRows<6>(kEkfQd) += u_t.transpose();
    Matrix6d z;
    z.noalias() = P_.block<6, 18>(kEkfQd, 0).lazyProduct(w.transpose());
    P_.leftCols<6>() += dt_s * P_.middleCols<6>(kEkfQd);
    P_.block<6, 6>(kEkfQd, kEkfQd) += z;
    constexpr int kFromD = kEkfPaddedSize - kEkfDisturbance;  // d and the biases
    P_.block<kFromD, 6>(kEkfDisturbance, kEkfQd) += u_t.bottomRows<kFromD>();
  } else {
    P_.middleRows<6>(kEkfQ) += dt_s * rows_v;
    P_.leftCols<6>() += dt_s * P_.middleCols<6>(kEkfQd);
  }
  MirrorLowerTriangle(&P_);
  for (int i = 0; i < 3; ++i) {
    AddWhiteAcceleration(i, sigma_lin, dt_s, &P_);
    AddWhiteAcceleration(i + 3, sigma_ang, dt_s, &P_);
  }
  if (!latency_accel_.isZero()) {
    // One sample of the acceleration error the latency allowance leaves,
    // along its direction (as AddWhiteAcceleration, for a vector).
    const Matrix6d e = latency_accel_ * latency_accel_.transpose();
    const double dt2 = dt_s * dt_s;
    P_.block<6, 6>(kEkfQ, kEkfQ) += (0.25 * dt2 * dt2) * e;
    P_.block<6, 6>(kEkfQ, kEkfQd) += (0.5 * dt2 * dt_s) * e;
    P_.block<6, 6>(kEkfQd, kEkfQ) += (0.5 * dt2 * dt_s) * e;
    P_.block<6, 6>(kEkfQd, kEkfQd) += dt2 * e;
  }
  // The legs' pose under a joint error moves against the gyro's reading as
  // fast as the platform moves, and its tilt against the accelerometer's
  // gravity (EstimatorConfig::gyro_bias_walk_per_speed,
  // accel_bias_walk_per_speed).
  const double speed_mps = qd.head<3>().norm() + platform_joint_radius_m_ * qd.tail<3>().norm();
  const double walk = config_.gyro_bias_walk_radps_per_sqrt_s;
  const double walk_moving = config_.gyro_bias_walk_per_speed * speed_mps;
  P_.diagonal().segment<3>(kEkfGyroBias).array() +=
      (walk * walk + walk_moving * walk_moving) * dt_s;
  if (EstimatesAccelBias()) {
    const double walk_a = config_.accel_bias_walk_mps2_per_sqrt_s;
    const double walk_a_moving = config_.accel_bias_walk_per_speed * speed_mps;
    const double variance_a = (walk_a * walk_a + walk_a_moving * walk_a_moving) * dt_s;
    P_.diagonal().segment<2>(kEkfAccelBias).array() += variance_a;
    if (config_.estimate_accel_bias_z) P_(kEkfAccelBias + 2, kEkfAccelBias + 2) += variance_a;
  }
  if (config_.estimate_disturbance) {
    const double walk_n = config_.disturbance_walk_n_per_sqrt_s;
    const double walk_nm = config_.disturbance_walk_nm_per_sqrt_s;
    P_.diagonal().segment<3>(kEkfDisturbance).array() += walk_n * walk_n * dt_s;
    P_.diagonal().segment<3>(kEkfDisturbance + 3).array() += walk_nm * walk_nm * dt_s;
  }
  if (force_change_allowed) {
    // d holds (M - M_true) qdd + H diag(gain - 1) F - H diag(F_c) sign(ld)
    // + ...: a change of the command changes those parts at once (the dry
    // friction when it reverses legs), by about a share of H dF, which d's
    // walk (sized for slow changes) cannot follow; the gyro and the
    // accelerometer then disagreed until gated (docs/estimator.md,
    // "Force-change allowance").
    if (previous_model_force_n_) {
      const double cap_n = config_.disturbance_force_change_cap_n;
      const Vector6d spread =
          config_.disturbance_force_change_std *
          (command->force_n - *previous_model_force_n_).cwiseMax(-cap_n).cwiseMin(cap_n);
      if (!spread.isZero()) {
        const Matrix6d h_spread = h_ * spread.asDiagonal();
        P_.block<6, 6>(kEkfDisturbance, kEkfDisturbance).noalias() +=
            h_spread * h_spread.transpose();
      }
    }
    previous_model_force_n_ = command->force_n;
  } else {
    previous_model_force_n_.reset();
  }
  if (friction_flip_allowed) {
    // A leg's dry friction -F_c sign(ld) flips by up to 2 F_c when the leg
    // reverses, whether or not the command changed (a leg creeping through
    // zero speed under a steady command): d's share of it jumps at once,
    // while d's walk is sized for slow changes. The estimate's leg speeds
    // ld = H^T qd at the interval's start tell when; a leg counts as
    // reversed when its speed, last beyond friction_flip_speed_mps one way,
    // is beyond it the other way, so that a leg dithering about zero (the
    // estimate's noise, a filter switching cases) does not open d on every
    // tick (docs/estimator.md, "Friction-flip allowance").
    const Vector6d leg_speed_mps = h_.transpose() * qd;
    const double band_mps = config_.disturbance_friction_flip_speed_mps;
    const Vector6d direction =
        (leg_speed_mps.array() > band_mps)
            .select(
                Vector6d::Ones(),
                (leg_speed_mps.array() < -band_mps).select(-Vector6d::Ones(), Vector6d::Zero()));
    if (previous_leg_direction_) {
      const double flip_std_n = config_.disturbance_friction_flip_std_n;
      const Vector6d spread = (direction.array() * previous_leg_direction_->array() < 0.0)
                                  .select(Vector6d::Constant(flip_std_n), Vector6d::Zero());
      if (!spread.isZero()) {
        const Matrix6d h_spread = h_ * spread.asDiagonal();
        P_.block<6, 6>(kEkfDisturbance, kEkfDisturbance).noalias() +=
            h_spread * h_spread.transpose();
      }
      // A leg within the band keeps the direction it last had.
      const Vector6d kept = (direction.array() != 0.0).select(direction, *previous_leg_direction_);
      previous_leg_direction_ = kept;
    } else {
      previous_leg_direction_ = direction;
    }
  } else {
    previous_leg_direction_.reset();
  }
}

void Ekf::RestoreDisturbanceBeforeDriveOn() {
  x_.segment<6>(kEkfDisturbance) = d_before_drive_on_;
  P_.middleRows<6>(kEkfDisturbance).setZero();
  P_.middleCols<6>(kEkfDisturbance).setZero();
  P_.block<6, 6>(kEkfDisturbance, kEkfDisturbance) = p_dd_before_drive_on_;
}

Vector6d Ekf::LatencyAccelerationError(const TimedCommand& command, int64_t interval_start_utime,
                                       const Vector6d& qd) const {
  // With the actuators' latency anywhere in [command_latency_s,
  // command_latency_s + allowance], the command acting over the interval is
  // the model's or one issued before it, back to the one acting at the
  // allowance's far end. Each differs from the model's prediction by
  // M^-1 H (F' - F), or, for a command that held the legs (the drive off:
  // the first samples after the drive comes on), by the held legs' motion
  // minus the predicted one. Unmodelled, a command that arrived late was
  // taken as model error d within one sample: 5.4 N learnt for 2.9 N on a
  // light platform at arming, which then fell at 0.06 m/s (docs/estimator.md,
  // "Latency allowance").
  const int64_t far_end_utime =
      interval_start_utime -
      static_cast<int64_t>(
          std::llround((config_.command_latency_s + config_.command_latency_allowance_s) / kUsToS));
  Vector6d worst = Vector6d::Zero();
  double worst_norm = 0.0;
  bool older = false;
  for (int k = 0; k < command_count_; ++k) {
    const TimedCommand& c = command_history_[static_cast<size_t>(
        (command_next_ - 1 - k + kCommandHistory) % kCommandHistory)];
    if (&c == &command) {
      older = true;
      continue;
    }
    if (!older) continue;
    const bool held =
        c.drive_off || (actuators_.kind == ActuatorKind::kDcMotor && c.force_n.isZero());
    const Vector6d e = held ? Vector6d(-qd / hold_time_constant_s_ - qdd_)
                            : Vector6d(dqdd_dforce_ * (c.force_n - command.force_n));
    const double norm = e.squaredNorm();
    if (e.allFinite() && norm > worst_norm) {
      worst = e;
      worst_norm = norm;
    }
    if (c.utime <= far_end_utime) break;
  }
  // One of two forces acting, the model's with probability p: the spread
  // about the model's is sqrt(p (1 - p)) |e| <= |e| / 2.
  return 0.5 * worst;
}

template <int M, int NB>
bool Ekf::Correct(const Eigen::Matrix<double, M, 1>& y, const std::array<int, NB>& blocks,
                  const Eigen::Matrix<double, M, 3 * NB>& h, const Eigen::Matrix<double, M, M>& R,
                  double* nis, bool gate_only) {
  // P H^T and S = H P H^T + R from the non-zero blocks of H only.
  Eigen::Matrix<double, kEkfPaddedSize, M> pht;  // padding rows (if any): zero
  pht.noalias() =
      P_.template middleCols<3>(blocks[0]).lazyProduct(h.template leftCols<3>().transpose());
  for (int b = 1; b < NB; ++b) {
    pht.noalias() += P_.template middleCols<3>(blocks[b]).lazyProduct(
        h.template middleCols<3>(3 * b).transpose());
  }
  Eigen::Matrix<double, M, M> S = R;
  for (int b = 0; b < NB; ++b) {
    S.noalias() +=
        h.template middleCols<3>(3 * b).lazyProduct(pht.template middleRows<3>(blocks[b]));
  }
  // S = L D L^T. With Z = L^-1 (P H^T)^T and w = L^-1 y (one forward
  // substitution each), K y = Z^T D^-1 w, K S K^T = Z^T D^-1 Z and
  // y^T S^-1 y = w^T D^-1 w.
  LdltSmall<M> ldlt;
  if (!ldlt.Compute(S)) return false;
  Eigen::Matrix<double, M, 1> w = y;
  for (int k = 0; k < M; ++k) {
    for (int i = k + 1; i < M; ++i) {
      w(i) -= ldlt.l(i, k) * w(k);
      pht.col(i) -= ldlt.l(i, k) * pht.col(k);
    }
  }
  const Eigen::Matrix<double, M, 1> w_scaled = w.cwiseProduct(ldlt.inv_d);
  *nis = w.dot(w_scaled);
  if (!(*nis <= config_.gating_chi2)) return false;  // also rejects NaN
  if (gate_only) return true;
  x_.noalias() += pht.template topRows<kEkfStateSize>() * w_scaled;
  // P -= G G^T with G = Z^T D^-1/2 (symmetric to the last bit).
  for (int k = 0; k < M; ++k) pht.col(k) *= std::sqrt(ldlt.inv_d(k));
  SubtractGram(pht, &P_);
  return true;
}

void Ekf::CorrectLegs(const Vector6d& leg_length_m, const EulerAngleTrig& trig, uint32_t* events) {
  Vector6d predicted;
  Matrix6d J;
  PredictLegLengths(params_, Vector6d(x_.segment<6>(kEkfQ)), trig, &predicted, &J);
  const Matrix6d R = Matrix6d::Identity() * leg_variance_m2_;
  const Vector6d y = leg_length_m - predicted;
  if (Correct<6, 2>(y, {kEkfQ, kEkfQ + 3}, J, R, &last_leg_nis_)) {
    consecutive_leg_rejections_ = 0;
    return;
  }
  ++consecutive_leg_rejections_;
  if (ReopenPoseAfterUnmodelledForce() &&
      Correct<6, 2>(y, {kEkfQ, kEkfQ + 3}, J, R, &last_leg_nis_)) {
    *events |= kEventPoseReopened;
    consecutive_leg_rejections_ = 0;
    return;
  }
  *events |= kGateLegs;
}

bool Ekf::ReopenPoseAfterUnmodelledForce() {
  // The legs disagree for a few samples in a row while the accelerometer
  // disagrees too, or did so lately: not a bad leg reading but a force the
  // model lacks (a heavier platform armed, a push), which moved the platform
  // away from the prediction before d could follow: by up to M^-1 d T^2/2 in
  // pose and M^-1 d T in velocity, d of a jump's size acting since the
  // accelerometer's disagreement began. Widening the pose and velocity
  // uncertainty by that much lets the legs back in. Without it they stayed
  // gated until the estimate restarted (through hw_bridge, a platform 0.33 kg
  // heavier than the model restarted it twice while arming, and the
  // supervisor held instead of arming). At most once per
  // kMinReopenIntervalS: against a plant whose joints are not the model's
  // the legs disagree every few samples, and re-opening each time would grow
  // the pose uncertainty without bound; legs that still disagree end in a
  // restart as before.
  const bool reopened_lately =
      pose_reopened_utime_ &&
      static_cast<double>(last_utime_ - *pose_reopened_utime_) * kUsToS < kMinReopenIntervalS;
  if (!config_.estimate_disturbance || reopened_lately ||
      consecutive_leg_rejections_ < kReopenAfterGatedLegs ||
      samples_since_accel_disagreed_ > config_.divergence_rejections) {
    return false;
  }
  pose_reopened_utime_ = last_utime_;
  const double window_s =
      std::clamp(static_cast<double>(last_utime_ - accel_disagreement_start_utime_) * kUsToS, 0.0,
                 kMaxReopenWindowS);
  Vector6d jump_std;
  jump_std << Vector3d::Constant(config_.disturbance_jump_std_n),
      Vector3d::Constant(config_.disturbance_jump_std_nm);
  Eigen::Matrix<double, 12, 6> drift;  // d(q, qd) / d(force), over the window
  drift.topRows<6>() = (0.5 * window_s * window_s) * m_inv_;
  drift.bottomRows<6>() = window_s * m_inv_;
  drift *= jump_std.asDiagonal();
  P_.topLeftCorner<12, 12>().noalias() += drift * drift.transpose();
  return true;
}

void Ekf::CorrectGyro(const Vector3d& gyro_radps, const EulerAngleTrig& trig, uint32_t* events) {
  Vector3d predicted;
  Eigen::Matrix<double, 3, 9> h;
  Matrix3d d_angles, d_rates;
  PredictGyro(trig, Vector6d(x_.segment<6>(kEkfQd)), x_.segment<3>(kEkfGyroBias), &predicted,
              &d_angles, &d_rates);
  h << d_angles, d_rates, Matrix3d::Identity();
  const Vector3d y = gyro_radps - predicted;
  const Matrix3d R = Matrix3d::Identity() * gyro_variance_;
  constexpr std::array<int, 3> kBlocks{kEkfQ + 3, kEkfQd + 3, kEkfGyroBias};
  double nis = 0.0;
  if (Correct<3, 3>(y, kBlocks, h, R, &nis)) {
    consecutive_gyro_gated_ = 0;
    return;
  }
  // The gyro disagrees sample after sample: not a bad reading but angular
  // rates the model mispredicts (a payload's inertia, joints that are not
  // the model's). Gated, the rates drifted on the model alone while their
  // covariance with the pose and the velocity grew, and the first reading
  // the gate let back in moved the whole state at once (bounds campaign,
  // random scenario: 37 gated samples, then z 9 mm and zd 0.42 m/s off in
  // one update, the platform driven to 0.1 m/s). Widening the rates'
  // uncertainty by the rates that explain the disagreement,
  // P_rr += delta delta^T with d_rates delta = y, lets the gyro in (y^T S^-1 y
  // = a / (1 + a) < 1, a the NIS before) and makes the correction follow it
  // through the rates rather than through their covariances.
  if (++consecutive_gyro_gated_ >= kReopenAfterGatedGyro) {
    const Eigen::PartialPivLU<Matrix3d> lu(d_rates);
    const Vector3d delta = lu.solve(y);
    if (delta.allFinite()) {
      P_.block<3, 3>(kEkfQd + 3, kEkfQd + 3).noalias() += delta * delta.transpose();
      if (Correct<3, 3>(y, kBlocks, h, R, &nis)) {
        *events |= kEventRatesReopened;
        consecutive_gyro_gated_ = 0;
        return;
      }
    }
  }
  *events |= kGateGyro;
}

void Ekf::CorrectAccel(const Vector3d& accel_mps2, const EulerAngleTrig& trig, uint32_t* events) {
  Vector3d predicted;
  AccelJacobians j;
  PredictAccel(trig, Vector6d(x_.segment<6>(kEkfQd)), qdd_, imu_offset_m_, params_.gravity_mps2,
               &predicted, &j);
  // The accelerometer reads the specific force plus its bias (d/db_a = I;
  // held at zero, with no uncertainty, when it is not estimated).
  predicted += x_.segment<3>(kEkfAccelBias);
  // The predicted qdd is uncertain by the process model's acceleration noise.
  const double sigma =
      qdd_from_dynamics_ ? AccelUpdateDynamicsStd(config_) : config_.process_accel_std_mps2;
  Matrix3d R = Matrix3d::Identity() * (accel_variance_ + sigma * sigma);
  if (qdd_from_dynamics_) {
    // ... and by the state's: the dynamics model's qdd depends on q and qd
    // (friction, Coriolis, gravity). Added to the noise, not to H, so the
    // accelerometer does not correct the pose through the dynamics; without
    // it the innovation covariance ignores the velocity's uncertainty and
    // right after an initialisation good samples are gated.
    // With T = (d_qdd [A B])^T (12x3): R += T^T P_[q,qd] T.
    const Eigen::Matrix<double, 6, 3> d_t = j.d_qdd.transpose();
    Eigen::Matrix<double, 12, 3> t;
    t.topRows<6>().noalias() = dqdd_dq_.transpose() * d_t;
    t.bottomRows<6>().noalias() = dqdd_dqd_.transpose() * d_t;
    const Eigen::Matrix<double, 12, 3> pt = P_.topLeftCorner<12, 12>().lazyProduct(t);
    R.noalias() += t.transpose() * pt;
    // ... and by the command the actuators may apply instead (Predict).
    const Vector3d latency = j.d_qdd * latency_accel_;
    R.noalias() += latency * latency.transpose();
  }
  double nis = 0.0;
  const Vector3d y = accel_mps2 - predicted;
  if (!(config_.estimate_disturbance && qdd_from_dynamics_)) {
    bool used = false;
    if (EstimatesAccelBias()) {
      Eigen::Matrix<double, 3, 9> h;
      h << j.d_angles, j.d_rates, Matrix3d::Identity();
      used = Correct<3, 3>(y, {kEkfQ + 3, kEkfQd + 3, kEkfAccelBias}, h, R, &nis);
    } else {
      Eigen::Matrix<double, 3, 6> h;
      h << j.d_angles, j.d_rates;
      used = Correct<3, 2>(y, {kEkfQ + 3, kEkfQd + 3}, h, R, &nis);
    }
    if (!used) *events |= kGateAccel;
    return;
  }
  // The specific force sees qdd, and qdd sees d through M^-1: the
  // accelerometer is what makes d observable within a few samples.
  // (The bias's block only when it is estimated: its zero covariance would
  // cost the products and change nothing.)
  Eigen::Matrix<double, 3, 15> h;
  h << j.d_angles, j.d_rates, j.d_qdd * m_inv_, Matrix3d::Identity();
  const std::array<int, 5> blocks = {kEkfQ + 3, kEkfQd + 3, kEkfDisturbance, kEkfDisturbance + 3,
                                     kEkfAccelBias};
  const auto correct = [&](const Matrix3d& r, bool gate_only) {
    return EstimatesAccelBias()
               ? Correct<3, 5>(y, blocks, h, r, &nis, gate_only)
               : Correct<3, 4>(y, {blocks[0], blocks[1], blocks[2], blocks[3]},
                               Eigen::Matrix<double, 3, 12>(h.leftCols<12>()), r, &nis, gate_only);
  };
  if (correct(R, false)) {
    consecutive_accel_gated_ = 0;
    samples_since_accel_disagreed_ = std::min(samples_since_accel_disagreed_ + 1, kNeverDisagreed);
    return;
  }
  // A disagreement starts: when the unmodelled force began to act.
  if (samples_since_accel_disagreed_ > config_.disturbance_jump_after_samples) {
    accel_disagreement_start_utime_ = last_utime_;
  }
  const int calm_samples = samples_since_accel_disagreed_;
  samples_since_accel_disagreed_ = 0;
  // Jump on the first gated sample instead of the jump_after_samples-th
  // when the accelerometer agreed for the calm samples before (no transient
  // of earlier commands is under way) and the innovation stays beyond the
  // gate whatever share of it a late command could explain (the latency
  // allowance's direction l freed): the samples waited for would only
  // confirm a step while it moves the platform unmodelled. Without the calm
  // condition a jump that overshoots is followed by another, and d chatters.
  const auto jumps_early = [&] {
    const int calm_needed = config_.disturbance_early_jump_calm_samples;
    if (calm_needed <= 0 || consecutive_accel_gated_ != 1 || calm_samples < calm_needed) {
      return false;
    }
    const Vector3d l = j.d_qdd * latency_accel_;
    const Matrix3d r_latency_freed = R + kLatencyDirectionFreed * (l * l.transpose());
    return !correct(r_latency_freed, true);
  };
  // Beyond the gate for long enough to be a step in d (a push, a payload set
  // down) that the random walk cannot follow, not the transient of a command
  // the actuators apply later than the model assumes: re-open d's
  // uncertainty and use the sample.
  ++consecutive_accel_gated_;
  const bool early = consecutive_accel_gated_ < config_.disturbance_jump_after_samples;
  if (early && !jumps_early()) {
    *events |= kGateAccel;
    return;
  }
  // One sample cannot tell a push from a bad reading (a glitch, a plant
  // whose legs are not yet held at its start reads free fall): an early
  // jump that moves d's force rows by more than any step the platform is
  // specified for is undone and waits for the next sample, as without it.
  EkfVector x_before_early_jump;
  PaddedMatrix p_before_early_jump;
  if (early) {
    x_before_early_jump = x_;
    p_before_early_jump = P_;
  }
  consecutive_accel_gated_ = 0;
  const double jump_n = config_.disturbance_jump_std_n;
  const double jump_nm = config_.disturbance_jump_std_nm;
  // Raised to the jump's variance, not by it: repeated jumps (a run of bad
  // samples) must not grow d's uncertainty without bound.
  P_.diagonal().segment<3>(kEkfDisturbance) =
      P_.diagonal().segment<3>(kEkfDisturbance).cwiseMax(jump_n * jump_n);
  P_.diagonal().segment<3>(kEkfDisturbance + 3) =
      P_.diagonal().segment<3>(kEkfDisturbance + 3).cwiseMax(jump_nm * jump_nm);
  if (!correct(R, false)) {
    *events |= kGateAccel;
    return;
  }
  if (early &&
      (x_.segment<3>(kEkfDisturbance) - x_before_early_jump.segment<3>(kEkfDisturbance)).norm() >
          config_.disturbance_early_jump_max_step_n) {
    x_ = x_before_early_jump;
    P_ = p_before_early_jump;
    consecutive_accel_gated_ = 1;  // the first gated sample, as without the early jump
    *events |= kGateAccel;
    return;
  }
  *events |= kEventDisturbanceJump;
}

void Ekf::CorrectOrientation(const Vector3d& rpy_rad, uint32_t* events) {
  Vector3d y = rpy_rad - x_.segment<3>(kEkfQ + 3);
  for (int i = 0; i < 3; ++i) y(i) = WrapAngle(y(i));
  double nis = 0.0;
  if (!Correct<3, 1>(y, {kEkfQ + 3}, Matrix3d::Identity(),
                     Matrix3d::Identity() * orientation_variance_, &nis)) {
    *events |= kGateOrientation;
  }
}

UpdateResult Ekf::Update(const SensorSample& sample) {
  UpdateResult result;
  uint32_t& events = result.events;
  // A sample out of time order is dropped whole, before any of it is judged.
  if (initialized_ && sample.utime <= last_utime_) {
    events |= kRejectTime;
    return result;
  }
  const bool legs_ok = LegsUsable(sample, &events);
  if (!initialized_) {
    if (!legs_ok || !InitializeFromLegs(sample, &events)) return result;
    diverged_ = false;
    result.has_estimate = true;
    return result;
  }
  const int64_t dt_us = sample.utime - last_utime_;
  const double dt_s = static_cast<double>(dt_us) * kUsToS;
  if (dt_s > config_.max_dt_s) {
    events |= kEventReinitTimeGap;
    initialized_ = false;
    if (!legs_ok || !InitializeFromLegs(sample, &events)) return result;
    result.has_estimate = true;
    return result;
  }
  // One sincos per angle per update: the corrections move the angles by
  // little, so their sines and cosines follow by the angle-sum formulas.
  Vector3d angles = x_.segment<3>(kEkfQ + 3);
  EulerAngleTrig trig(angles);
  const auto follow_angles = [&]() {
    const Vector3d now = x_.segment<3>(kEkfQ + 3);
    trig = ShiftEulerAngleTrig(trig, now - angles, now);
    angles = now;
  };
  Predict(dt_s, sample.utime, trig, sample.drive_off, &events);
  last_utime_ = sample.utime;
  if (legs_ok) {
    follow_angles();
    CorrectLegs(sample.leg_length_m, trig, &events);
  } else {
    // The legs are the only absolute measurement of the pose: without them
    // the estimate is a prediction, bridged for as many samples as a gated
    // leg update, then given up (a sensor that only sends NaN).
    ++consecutive_leg_rejections_;
  }
  if (sample.imu_valid) {
    if (sample.gyro_radps.allFinite() &&
        sample.gyro_radps.cwiseAbs().maxCoeff() <= config_.max_gyro_radps) {
      follow_angles();
      CorrectGyro(sample.gyro_radps, trig, &events);
    } else {
      events |= kRejectGyroInvalid;
    }
    if (config_.use_accelerometer) {
      if (sample.accel_mps2.allFinite() &&
          sample.accel_mps2.cwiseAbs().maxCoeff() <= config_.max_accel_mps2) {
        follow_angles();
        CorrectAccel(sample.accel_mps2, trig, &events);
      } else {
        events |= kRejectAccelInvalid;
      }
    }
    if (sample.has_orientation) {
      if (sample.orientation_rpy_rad.allFinite()) {
        CorrectOrientation(sample.orientation_rpy_rad, &events);
      } else {
        events |= kRejectOrientationInvalid;
      }
    }
  }
  ++samples_since_init_;
  // The drive may not act yet (Predict): nothing this sample said of d is kept.
  if (drive_on_window_) RestoreDisturbanceBeforeDriveOn();

  // Divergence: the legs keep disagreeing with the estimate, or the filter
  // arithmetic broke down. Either way restart from the legs.
  const bool broken =
      !AllFinite(x_) || !AllFinite(P_) ||
      P_.diagonal().segment<3>(kEkfQ).maxCoeff() > kMaxPositionStdM * kMaxPositionStdM;
  if (broken || consecutive_leg_rejections_ >= config_.divergence_rejections) {
    events |= kEventDiverged;
    diverged_ = true;
    if (broken) initialized_ = false;
    if (!legs_ok || !InitializeFromLegs(sample, &events)) {
      initialized_ = false;
      return result;
    }
  }
  result.has_estimate = true;
  return result;
}

Ekf::PaddedMatrix Ekf::PaddedIdentity() {
  PaddedMatrix p = PaddedMatrix::Zero();
  p.diagonal().head<kEkfStateSize>().setOnes();
  return p;
}

Estimate Ekf::estimate() const {
  Estimate e;
  e.utime = last_utime_;
  e.q = x_.segment<6>(kEkfQ);
  e.qd = x_.segment<6>(kEkfQd);
  e.q_std = P_.diagonal().segment<6>(kEkfQ).cwiseMax(0.0).cwiseSqrt();
  e.qd_std = P_.diagonal().segment<6>(kEkfQd).cwiseMax(0.0).cwiseSqrt();
  e.gyro_bias_radps = x_.segment<3>(kEkfGyroBias);
  e.accel_bias_mps2 = x_.segment<3>(kEkfAccelBias);
  e.disturbance_n = x_.segment<6>(kEkfDisturbance);
  e.disturbance_std_n = P_.diagonal().segment<6>(kEkfDisturbance).cwiseMax(0.0).cwiseSqrt();
  e.initializing = samples_since_init_ < config_.settle_samples;
  e.diverged = diverged_ && e.initializing;
  return e;
}

}  // namespace stewart
