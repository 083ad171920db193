#pragma once
// A DeviceBackend on the rigid-body model of model/ (paper eq. 2), integrated
// with fixed-step RK4. Stand-in until plant_sim's library (the simulator's
// plant and sensor models) can back the emulator.
#include <random>

#include "stewart/config/hw_bridge_config.h"
#include "stewart/config/platform_config.h"
#include "stewart/config/sensor_config.h"
#include "stewart/hw_bridge/calibration.h"
#include "stewart/hw_bridge/drive_map.h"
#include "stewart/hw_emulator/device_backend.h"
#include "stewart/model/dynamics.h"

namespace stewart::hw {

struct ModelBackendOptions {
  double substep_s = 1e-4;  ///< RK4 step; the endstop spring needs < ~3e-4 s
  /// A leg whose duty is within the deadband self-locks (the lead screw is not
  /// back-drivable). Modelled as this viscous lock unless all six are locked,
  /// in which case the platform is frozen exactly.
  double lock_damping_nspm = 5.0e3;
  bool noise = true;  ///< sensor noise and bias from the sensors section
};

class ModelBackend final : public DeviceBackend {
 public:
  ModelBackend(const PlatformParams& platform, const ActuatorConfig& actuators,
               const SensorConfig& sensors, const HwBridgeConfig& hw, const Vector6d& q0,
               const Vector6d& qd0, const ModelBackendOptions& options = {});

  void Step(const DriveArray& drive, double dt_s) override;
  RawReadings Sample() override;

  const Vector6d& q() const { return q_; }
  const Vector6d& qd() const { return qd_; }
  /// Leg forces (N) the last step applied, friction and endstops included.
  const Vector6d& leg_force_n() const { return leg_force_n_; }

 private:
  /// qdd at (q, qd) under drive force f_drive; also returns the leg forces.
  Vector6d Acceleration(const Vector6d& q, const Vector6d& qd, const Vector6d& f_drive,
                        const std::array<bool, 6>& locked, Vector6d* leg_force_n);

  PlatformParams platform_;
  ActuatorConfig actuators_;
  SensorConfig sensors_;
  ModelBackendOptions options_;
  LegCalibration calibration_;
  ImuScale imu_;
  DriveMap drive_map_;
  int adc_max_;
  DynamicsTerms terms_;
  Vector6d q_;
  Vector6d qd_;
  Vector6d qdd_ = Vector6d::Zero();
  Vector6d leg_force_n_ = Vector6d::Zero();
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace stewart::hw
