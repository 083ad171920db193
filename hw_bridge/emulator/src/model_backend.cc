#include "stewart/hw_emulator/model_backend.h"

#include <algorithm>
#include <cmath>

#include "stewart/hw_bridge/wire_format.h"
#include "stewart/model/imu.h"

namespace stewart::hw {

ModelBackend::ModelBackend(const PlatformParams& platform, const ActuatorConfig& actuators,
                           const SensorConfig& sensors, const HwBridgeConfig& hw,
                           const Vector6d& q0, const Vector6d& qd0,
                           const ModelBackendOptions& options)
    : platform_(platform),
      actuators_(actuators),
      sensors_(sensors),
      options_(options),
      calibration_(hw, platform.leg_min_length_m,
                   platform.leg_max_length_m - platform.leg_min_length_m),
      imu_(hw),
      drive_map_(hw, actuators.force_limit_n),
      adc_max_(hw.adc_max_count),
      q_(q0),
      qd_(qd0),
      rng_(sensors.seed) {
  // At rest the accelerometer reads +g even with all legs locked.
  EvaluateDynamics(platform_, q_, qd_, &terms_);
}

Vector6d ModelBackend::Acceleration(const Vector6d& q, const Vector6d& qd, const Vector6d& f_drive,
                                    const std::array<bool, 6>& locked, Vector6d* leg_force_n) {
  EvaluateDynamics(platform_, q, qd, &terms_);
  const Vector6d leg_speed = terms_.H.transpose() * qd;  // ld = J_l qd, H = J_l^T
  Vector6d f = Vector6d::Zero();
  for (int i = 0; i < kNumLegs; ++i) {
    const double damping = locked[static_cast<std::size_t>(i)] ? options_.lock_damping_nspm
                                                               : actuators_.viscous_friction_nspm;
    f(i) = f_drive(i) - damping * leg_speed(i);
    // Stroke ends: a stiff spring-damper beyond each end.
    const double below = platform_.leg_min_length_m - terms_.leg_length_m(i);
    const double above = terms_.leg_length_m(i) - platform_.leg_max_length_m;
    if (below > 0.0) {
      f(i) +=
          actuators_.endstop_stiffness_npm * below - actuators_.endstop_damping_nspm * leg_speed(i);
    } else if (above > 0.0) {
      f(i) -=
          actuators_.endstop_stiffness_npm * above + actuators_.endstop_damping_nspm * leg_speed(i);
    }
  }
  *leg_force_n = f;
  return ForwardDynamics(terms_, f);
}

void ModelBackend::Step(const DriveArray& drive, double dt_s) {
  const std::array<bool, 6> locked = drive_map_.Locked(drive);
  if (std::all_of(locked.begin(), locked.end(), [](bool l) { return l; })) {
    // Six locked legs fix the pose: the platform holds exactly.
    qd_.setZero();
    qdd_.setZero();
    leg_force_n_.setZero();
    return;
  }
  const Vector6d f_drive = drive_map_.DriveToForce(drive);
  const int steps = std::max(1, static_cast<int>(std::ceil(dt_s / options_.substep_s - 1e-9)));
  const double h = dt_s / steps;
  Vector6d unused;
  for (int s = 0; s < steps; ++s) {
    const Vector6d a1 = Acceleration(q_, qd_, f_drive, locked, &unused);
    const Vector6d v1 = qd_;
    const Vector6d v2 = qd_ + 0.5 * h * a1;
    const Vector6d a2 = Acceleration(q_ + 0.5 * h * v1, v2, f_drive, locked, &unused);
    const Vector6d v3 = qd_ + 0.5 * h * a2;
    const Vector6d a3 = Acceleration(q_ + 0.5 * h * v2, v3, f_drive, locked, &unused);
    const Vector6d v4 = qd_ + h * a3;
    const Vector6d a4 = Acceleration(q_ + h * v3, v4, f_drive, locked, &unused);
    q_ += h / 6.0 * (v1 + 2.0 * v2 + 2.0 * v3 + v4);
    qd_ += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
  }
  qdd_ = Acceleration(q_, qd_, f_drive, locked, &leg_force_n_);
}

RawReadings ModelBackend::Sample() {
  RawReadings raw;
  EvaluateDynamics(platform_, q_, qd_, &terms_);
  const double noise = options_.noise ? 1.0 : 0.0;
  constexpr double kEndstopBand_m = 5e-4;
  for (int i = 0; i < kNumLegs; ++i) {
    const double l = terms_.leg_length_m(i);
    if (l < platform_.leg_min_length_m + kEndstopBand_m ||
        l > platform_.leg_max_length_m - kEndstopBand_m) {
      raw.status |= kStatusEndstop;
    }
    const double measured = l + noise * sensors_.leg_pot_noise_std_m * normal_(rng_);
    const double counts = std::round(calibration_.AdcCounts(i, measured));
    raw.adc[static_cast<std::size_t>(i)] =
        static_cast<uint16_t>(std::clamp(counts, 0.0, static_cast<double>(adc_max_)));
  }
  Vector3d gyro = BodyAngularVelocity(q_, qd_) + noise * sensors_.gyro_bias_radps;
  Vector3d accel = ImuSpecificForce(q_, qd_, qdd_, sensors_.imu_offset_m, platform_.gravity_mps2) +
                   noise * sensors_.accel_bias_mps2;
  for (int k = 0; k < 3; ++k) {
    gyro(k) += noise * sensors_.gyro_noise_std_radps * normal_(rng_);
    accel(k) += noise * sensors_.accel_noise_std_mps2 * normal_(rng_);
  }
  const bool gyro_ok = imu_.GyroRaw(gyro, &raw.gyro_raw);
  const bool accel_ok = imu_.AccelRaw(accel, &raw.accel_raw);
  if (!gyro_ok || !accel_ok) raw.status |= kStatusImuFault;
  return raw;
}

}  // namespace stewart::hw
