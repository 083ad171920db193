#include "stewart/estimator/ekf.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "stewart/estimator/measurement_models.h"
#include "stewart/estimator/process_model.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

constexpr double kUsToS = 1e-6;
// An estimate this uncertain is no estimate: restart instead of publishing it.
constexpr double kMaxPositionStdM = 0.05;

// Discrete white-noise acceleration (one sample of constant acceleration with
// std sigma) on the (q_i, qd_i) pair of axis i.
void AddWhiteAcceleration(int axis, double sigma, double dt_s, EkfMatrix* P) {
  const double v = sigma * sigma;
  const double dt2 = dt_s * dt_s;
  (*P)(kEkfQ + axis, kEkfQ + axis) += v * 0.25 * dt2 * dt2;
  (*P)(kEkfQ + axis, kEkfQd + axis) += v * 0.5 * dt2 * dt_s;
  (*P)(kEkfQd + axis, kEkfQ + axis) += v * 0.5 * dt2 * dt_s;
  (*P)(kEkfQd + axis, kEkfQd + axis) += v * dt2;
}

}  // namespace

Ekf::Ekf(const PlatformParams& params, const ActuatorConfig& actuators, const SensorConfig& sensors,
         const EstimatorConfig& config, const Vector6d& home_pose)
    : params_(params),
      actuators_(actuators),
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
  gyro_variance_ = std::max(sensors.gyro_noise_std_radps * sensors.gyro_noise_std_radps, 1e-14);
  accel_variance_ = std::max(sensors.accel_noise_std_mps2 * sensors.accel_noise_std_mps2, 1e-14);
  orientation_variance_ =
      std::max(sensors.orientation_noise_std_rad * sensors.orientation_noise_std_rad, 1e-14);
}

void Ekf::SetForceCommand(int64_t utime, const Vector6d& force_n) {
  if (!force_n.allFinite()) return;  // the node counts it; never feed NaN into the model
  has_command_ = true;
  command_utime_ = utime;
  command_n_ = force_n.cwiseMax(-actuators_.force_limit_n).cwiseMin(actuators_.force_limit_n);
}

void Ekf::Reset() {
  initialized_ = false;
  x_.setZero();
  P_.setIdentity();
  qdd_.setZero();
  consecutive_leg_rejections_ = 0;
  samples_since_init_ = 0;
}

void Ekf::Initialize(int64_t utime, const Vector6d& q, const Vector6d& qd, const EkfVector& std) {
  x_.segment<6>(kEkfQ) = q;
  x_.segment<6>(kEkfQd) = qd;
  x_.segment<3>(kEkfGyroBias).setZero();
  P_ = std.cwiseProduct(std).asDiagonal();
  qdd_.setZero();
  last_utime_ = utime;
  initialized_ = true;
  consecutive_leg_rejections_ = 0;
  samples_since_init_ = 0;
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
  Initialize(sample.utime, fk.q, Vector6d::Zero(), std);
  *events |= kEventInitialized;
  return true;
}

void Ekf::Predict(double dt_s, int64_t utime, uint32_t* events) {
  const Vector6d q = x_.segment<6>(kEkfQ);
  const Vector6d qd = x_.segment<6>(kEkfQd);
  const bool command_fresh =
      has_command_ &&
      utime - command_utime_ <= static_cast<int64_t>(config_.command_timeout_s / kUsToS);
  const bool use_dynamics =
      config_.process_model == EstimatorProcessModel::kDynamics && command_fresh;
  double sigma_lin = config_.process_accel_std_mps2;
  double sigma_ang = config_.process_angaccel_std_radps2;
  // Transition of [q; qd] to first order in dt: [[I, dt I], [dt A, I + dt B]]
  // with A = dqdd/dq, B = dqdd/dqd (zero for the constant-velocity model).
  Eigen::Matrix<double, 12, 12> phi = Eigen::Matrix<double, 12, 12>::Identity();
  phi.topRightCorner<6, 6>().diagonal().setConstant(dt_s);
  if (use_dynamics) {
    Matrix6d A, B;
    DynamicsAccelerationJacobians(params_, actuators_.viscous_friction_nspm, q, qd, command_n_,
                                  &qdd_, &A, &B);
    phi.bottomLeftCorner<6, 6>() = dt_s * A;
    phi.bottomRightCorner<6, 6>() += dt_s * B;
    dqdd_dq_ = A;
    dqdd_dqd_ = B;
    sigma_lin = config_.dynamics_accel_std_mps2;
    sigma_ang = config_.dynamics_angaccel_std_radps2;
  } else {
    if (config_.process_model == EstimatorProcessModel::kDynamics) *events |= kEventNoCommand;
    qdd_.setZero();
  }
  qdd_from_dynamics_ = use_dynamics;
  x_.segment<6>(kEkfQ) += dt_s * qd + 0.5 * dt_s * dt_s * qdd_;
  x_.segment<6>(kEkfQd) += dt_s * qdd_;

  // P <- Phi P Phi^T; the gyro bias rows and columns are unchanged by Phi.
  const Eigen::Matrix<double, 12, kEkfStateSize> top = phi * P_.topRows<12>();
  P_.topRows<12>() = top;
  const Eigen::Matrix<double, kEkfStateSize, 12> left = P_.leftCols<12>() * phi.transpose();
  P_.leftCols<12>() = left;
  for (int i = 0; i < 3; ++i) {
    AddWhiteAcceleration(i, sigma_lin, dt_s, &P_);
    AddWhiteAcceleration(i + 3, sigma_ang, dt_s, &P_);
  }
  const double walk = config_.gyro_bias_walk_radps_per_sqrt_s;
  P_.diagonal().segment<3>(kEkfGyroBias).array() += walk * walk * dt_s;
}

template <int M>
bool Ekf::Correct(const Eigen::Matrix<double, M, 1>& y,
                  const Eigen::Matrix<double, M, kEkfStateSize>& H,
                  const Eigen::Matrix<double, M, M>& R, double* nis) {
  using MatM = Eigen::Matrix<double, M, M>;
  using MatNM = Eigen::Matrix<double, kEkfStateSize, M>;
  const MatNM PHt = P_ * H.transpose();
  const MatM S = H * PHt + R;
  const Eigen::LLT<MatM> llt(S);
  if (llt.info() != Eigen::Success) return false;
  *nis = y.dot(llt.solve(y));
  if (!(*nis <= config_.gating_chi2)) return false;  // also rejects NaN
  const MatNM K = llt.solve(PHt.transpose()).transpose();
  x_ += K * y;
  P_ -= K * PHt.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return true;
}

void Ekf::CorrectLegs(const Vector6d& leg_length_m, uint32_t* events) {
  Vector6d predicted;
  MeasurementJacobian<6> H;
  PredictLegLengths(params_, x_, &predicted, &H);
  const Matrix6d R = Matrix6d::Identity() * leg_variance_m2_;
  if (Correct<6>(leg_length_m - predicted, H, R, &last_leg_nis_)) {
    consecutive_leg_rejections_ = 0;
  } else {
    *events |= kGateLegs;
    ++consecutive_leg_rejections_;
  }
}

void Ekf::CorrectGyro(const Vector3d& gyro_radps, uint32_t* events) {
  Vector3d predicted;
  MeasurementJacobian<3> H;
  PredictGyro(x_, &predicted, &H);
  double nis = 0.0;
  if (!Correct<3>(gyro_radps - predicted, H, Matrix3d::Identity() * gyro_variance_, &nis)) {
    *events |= kGateGyro;
  }
}

void Ekf::CorrectAccel(const Vector3d& accel_mps2, uint32_t* events) {
  Vector3d predicted;
  MeasurementJacobian<3> H;
  PredictAccel(x_, qdd_, imu_offset_m_, params_.gravity_mps2, &predicted, &H);
  // The predicted qdd is uncertain by the process model's acceleration noise.
  const double sigma =
      qdd_from_dynamics_ ? config_.dynamics_accel_std_mps2 : config_.process_accel_std_mps2;
  Matrix3d R = Matrix3d::Identity() * (accel_variance_ + sigma * sigma);
  if (qdd_from_dynamics_) {
    // ... and by the state's: the dynamics model's qdd depends on q and qd
    // (friction, Coriolis, gravity). Added to the noise, not to H, so the
    // accelerometer does not correct the pose through the dynamics; without
    // it the innovation covariance ignores the velocity's uncertainty and
    // right after an initialisation good samples are gated.
    Eigen::Matrix<double, 3, 12> d_state;
    const Eigen::Matrix<double, 3, 6> d =
        AccelQddJacobian(x_, qdd_, imu_offset_m_, params_.gravity_mps2);
    d_state << d * dqdd_dq_, d * dqdd_dqd_;
    R += d_state * P_.topLeftCorner<12, 12>() * d_state.transpose();
  }
  double nis = 0.0;
  if (!Correct<3>(accel_mps2 - predicted, H, R, &nis)) *events |= kGateAccel;
}

void Ekf::CorrectOrientation(const Vector3d& rpy_rad, uint32_t* events) {
  MeasurementJacobian<3> H = MeasurementJacobian<3>::Zero();
  H.block<3, 3>(0, kEkfQ + 3).setIdentity();
  Vector3d y = rpy_rad - x_.segment<3>(kEkfQ + 3);
  for (int i = 0; i < 3; ++i) y(i) = WrapAngle(y(i));
  double nis = 0.0;
  if (!Correct<3>(y, H, Matrix3d::Identity() * orientation_variance_, &nis)) {
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
  Predict(dt_s, sample.utime, &events);
  last_utime_ = sample.utime;
  if (legs_ok) CorrectLegs(sample.leg_length_m, &events);
  if (sample.imu_valid) {
    if (sample.gyro_radps.allFinite() &&
        sample.gyro_radps.cwiseAbs().maxCoeff() <= config_.max_gyro_radps) {
      CorrectGyro(sample.gyro_radps, &events);
    } else {
      events |= kRejectGyroInvalid;
    }
    if (config_.use_accelerometer) {
      if (sample.accel_mps2.allFinite() &&
          sample.accel_mps2.cwiseAbs().maxCoeff() <= config_.max_accel_mps2) {
        CorrectAccel(sample.accel_mps2, &events);
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

  // Divergence: the legs keep disagreeing with the estimate, or the filter
  // arithmetic broke down. Either way restart from the legs.
  const bool broken =
      !x_.allFinite() || !P_.allFinite() ||
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

Estimate Ekf::estimate() const {
  Estimate e;
  e.utime = last_utime_;
  e.q = x_.segment<6>(kEkfQ);
  e.qd = x_.segment<6>(kEkfQd);
  e.q_std = P_.diagonal().segment<6>(kEkfQ).cwiseMax(0.0).cwiseSqrt();
  e.qd_std = P_.diagonal().segment<6>(kEkfQd).cwiseMax(0.0).cwiseSqrt();
  e.gyro_bias_radps = x_.segment<3>(kEkfGyroBias);
  e.initializing = samples_since_init_ < config_.settle_samples;
  e.diverged = diverged_ && e.initializing;
  return e;
}

}  // namespace stewart
