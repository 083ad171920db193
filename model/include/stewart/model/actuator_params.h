#pragma once
// The legs' actuators as the model sees them (config section `actuators`).
// docs/model.md, "Actuators", gives every parameter's source and range.

namespace stewart {

/// What drives a leg.
enum class ActuatorKind {
  /// An ideal force source: the leg pushes with the commanded force (the
  /// paper's model and its figures).
  kIdealForce,
  /// A DC gear motor turning a self-locking lead screw behind an H-bridge
  /// (Actuonix P-16P / L16 class behind an L298N): the device's input is a
  /// PWM duty (model/dc_motor.h).
  kDcMotor,
};

/// The DC motor, gearbox and lead screw of one leg, referred to the leg axis
/// (forces in N along the leg, speeds dL/dt in m/s). Used when
/// ActuatorConfig::kind is kDcMotor.
struct DcMotorParams {
  double supply_voltage_v = 12.0;
  /// The H-bridge's total voltage drop while it conducts (V): the motor sees
  /// at most supply - drop.
  double bridge_drop_v = 0.0;
  /// |duty| at or below this gives the motor no torque (it does not start);
  /// above it the torque rises linearly to full at |duty| = 1.
  double dead_band_duty = 0.0;
  /// The voltage at which stall force and no-load speed are rated (V).
  double rated_voltage_v = 12.0;
  /// Force on the leg at zero speed with the rated voltage on the motor (N).
  double stall_force_n = 0.0;
  /// Leg speed at the rated voltage with no load (m/s): the back-EMF damping
  /// is b = stall_force_n / no_load_speed_mps (N s/m).
  double no_load_speed_mps = 0.0;
  /// The rotor's inertia seen along the leg, J (2 pi N / lead)^2 (kg).
  double reflected_mass_kg = 0.0;
  /// Dry friction of the screw and gearbox while the motor drives (N).
  double coulomb_friction_n = 0.0;
  /// With the motor not driving, the self-locking screw holds the leg
  /// against any axial load below this (N); above it the load back-drives it.
  double back_drive_force_n = 0.0;
  /// Stiffness of a held (self-locked) leg (N/m), the screw and gearbox
  /// compliance; its damping is critical with reflected_mass_kg.
  double lock_stiffness_npm = 0.0;
};

struct ActuatorConfig {
  ActuatorKind kind = ActuatorKind::kIdealForce;
  double min_length_m = 0.0;
  double stroke_m = 0.0;
  /// |F_i| <= this: the box of the stack's control input (for kDcMotor, the
  /// motor force the stack may ask for, at most DcMotorForceAtFullDuty).
  double force_limit_n = 0.0;
  double viscous_friction_nspm = 0.0;  ///< N per (m/s) of leg speed, the screw's own
  double force_lag_s = 0.0;            ///< first-order lag, 0 = none
  double endstop_stiffness_npm = 0.0;
  double endstop_damping_nspm = 0.0;
  DcMotorParams motor;  ///< kDcMotor only
};

}  // namespace stewart
