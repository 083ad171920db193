#pragma once
// Leg force (N) <-> signed drive command (PWM duty of the L298N, counts).
#include <array>
#include <cstdint>

#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/types.h"

namespace stewart::hw {

using DriveArray = std::array<int16_t, 6>;

struct DriveResult {
  DriveArray drive{};
  uint8_t force_clamped_mask = 0;  ///< bit i: |F_i| exceeded actuators.force_limit_n
  uint8_t duty_clamped_mask = 0;   ///< bit i: |duty_i| exceeded hw_bridge.max_duty
  /// bit i: 0 < |F_i| < force_deadzone_n, so a commanded force was not applied
  /// (zero drive). The stack assumes the commanded force acts: docs/hardware.md.
  uint8_t deadzone_mask = 0;
};

/// For each leg, with F_c = clamp(F, +-force_limit_n):
///   duty = 0                                                        if |F_c| < force_deadzone_n
///   duty = sign(F_c) (duty_deadband + (1 - duty_deadband) |F_c| / force_at_full_duty_n)  else
///          (DutyForForce, model/dc_motor.h)
///   duty = clamp(duty, +-max_duty);  drive = drive_sign_i round(duty * 32767)
/// The deadband term overcomes the lead screw's static friction: below it the
/// P-16P does not move. Positive force extends the leg.
class DriveMap {
 public:
  DriveMap(const HwBridgeConfig& hw, double force_limit_n);

  /// Non-finite forces must be rejected before; they give zero drive here.
  DriveResult ForceToDrive(const Vector6d& force_n) const;
  /// Bring-up (bringup.h): a duty per leg straight to the drive,
  /// drive = drive_sign_i round(clamp(duty, +-max_duty) * 32767); non-finite
  /// duty gives zero drive.
  DriveResult DutyToDrive(const Vector6d& duty) const;
  /// The inverse outside the clamps (the emulator's actuator model): a duty
  /// within the deadband gives zero force (the leg self-locks).
  Vector6d DriveToForce(const DriveArray& drive) const;
  /// The signed duty each leg's bridge receives, drive_sign_i drive_i / full scale.
  Vector6d Duty(const DriveArray& drive) const;
  /// True for legs whose duty is within the deadband (self-locked).
  std::array<bool, 6> Locked(const DriveArray& drive) const;

 private:
  double force_limit_n_;
  // The duty equation (model/dc_motor.h), unclamped: ForceToDrive clamps and
  // reports the clamps itself.
  ForceToDutyMap map_;
  double force_deadzone_n_;
  double max_duty_;
  Vector6d drive_sign_;
};

}  // namespace stewart::hw
