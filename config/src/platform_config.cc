#include <Eigen/Eigenvalues>

#include "stewart/config/sections.h"
#include "stewart/model/dc_motor.h"

namespace stewart {

PlatformParams ParsePlatformParams(const ConfigNode& root) {
  const ConfigNode platform = root.Child("platform");
  const ConfigNode legs = root.Child("legs");
  const ConfigNode actuators = root.Child("actuators");

  PlatformParams p;
  p.base_joints_in_B_m = JointsOnCircle(platform.PositiveDouble("base_joint_radius_m"),
                                        platform.Array6("base_joint_angles_deg"));
  p.platform_joints_in_P_m = JointsOnCircle(platform.PositiveDouble("platform_joint_radius_m"),
                                            platform.Array6("platform_joint_angles_deg"));
  p.platform_mass_kg = platform.PositiveDouble("mass_kg");
  p.platform_com_in_P_m = platform.Vec3("com_m");
  p.platform_inertia_kgm2 = platform.Vec3("inertia_kgm2");
  // Optional (zero for a body symmetric about {P}'s axes): an identified
  // platform or one with a payload off the axes has them.
  if (platform.Has("inertia_products_kgm2")) {
    p.platform_inertia_products_kgm2 = platform.Vec3("inertia_products_kgm2");
  }
  for (int i = 0; i < 3; ++i) {
    if (!(p.platform_inertia_kgm2(i) > 0.0)) {
      platform.Fail("inertia_kgm2", "principal inertias must be positive");
    }
  }
  // A rigid body's principal moments obey the triangle inequality; with
  // products of inertia the principal moments are the tensor's eigenvalues.
  const Vector3d I = Eigen::SelfAdjointEigenSolver<Matrix3d>(PlatformInertiaInP(p)).eigenvalues();
  if (!(I.minCoeff() > 0.0)) {
    platform.Fail("inertia_products_kgm2", "the inertia tensor is not positive definite");
  }
  // (A flat plate sits on the bound; the eigen-solver's rounding must not fail it.)
  const double tolerance = 1e-12 * I.sum();
  if (I(0) + I(1) < I(2) - tolerance || I(1) + I(2) < I(0) - tolerance ||
      I(0) + I(2) < I(1) - tolerance) {
    platform.Fail("inertia_kgm2", "violates the triangle inequality of a rigid body");
  }
  p.gravity_mps2 = platform.NonNegativeDouble("gravity_mps2");

  p.leg.cylinder_mass_kg = legs.NonNegativeDouble("cylinder_mass_kg");
  p.leg.cylinder_com_from_base_m = legs.NonNegativeDouble("cylinder_com_from_base_m");
  p.leg.cylinder_inertia_kgm2 = legs.NonNegativeDouble("cylinder_inertia_kgm2");
  p.leg.rod_mass_kg = legs.NonNegativeDouble("rod_mass_kg");
  p.leg.rod_com_from_platform_m = legs.NonNegativeDouble("rod_com_from_platform_m");
  p.leg.rod_inertia_kgm2 = legs.NonNegativeDouble("rod_inertia_kgm2");

  const ActuatorConfig actuator_config = ParseActuatorConfig(actuators);
  if (actuator_config.kind == ActuatorKind::kDcMotor) {
    p.leg.actuator_reflected_mass_kg = actuator_config.motor.reflected_mass_kg;
  }
  p.leg_min_length_m = actuators.PositiveDouble("min_length_m");
  p.leg_max_length_m = p.leg_min_length_m + actuators.PositiveDouble("stroke_m");
  if (p.leg.rod_com_from_platform_m >= p.leg_min_length_m) {
    legs.Fail("rod_com_from_platform_m", "must be shorter than actuators.min_length_m");
  }
  return p;
}

namespace {

DcMotorParams ParseDcMotorParams(const ConfigNode& motor) {
  DcMotorParams m;
  m.supply_voltage_v = motor.PositiveDouble("supply_voltage_v");
  m.bridge_drop_v = motor.NonNegativeDouble("bridge_drop_v");
  if (!(m.bridge_drop_v < m.supply_voltage_v)) {
    motor.Fail("bridge_drop_v", "must be below supply_voltage_v");
  }
  m.dead_band_duty = motor.NonNegativeDouble("dead_band_duty");
  if (!(m.dead_band_duty < 1.0)) motor.Fail("dead_band_duty", "must be < 1");
  m.rated_voltage_v = motor.PositiveDouble("rated_voltage_v");
  m.stall_force_n = motor.PositiveDouble("stall_force_n");
  m.no_load_speed_mps = motor.PositiveDouble("no_load_speed_mps");
  m.reflected_mass_kg = motor.NonNegativeDouble("reflected_mass_kg");
  m.coulomb_friction_n = motor.NonNegativeDouble("coulomb_friction_n");
  m.back_drive_force_n = motor.NonNegativeDouble("back_drive_force_n");
  m.lock_stiffness_npm = motor.PositiveDouble("lock_stiffness_npm");
  return m;
}

}  // namespace

ActuatorConfig ParseActuatorConfig(const ConfigNode& actuators) {
  ActuatorConfig a;
  // Optional: configs written for the ideal force source have no `model`.
  if (actuators.Has("model")) {
    a.kind = actuators.Choice("model", {"ideal_force", "dc_motor"}) == "dc_motor"
                 ? ActuatorKind::kDcMotor
                 : ActuatorKind::kIdealForce;
  }
  // Checked whenever present (an overlay may switch the model to it).
  if (a.kind == ActuatorKind::kDcMotor || actuators.Has("motor")) {
    a.motor = ParseDcMotorParams(actuators.Child("motor"));
  }
  a.min_length_m = actuators.PositiveDouble("min_length_m");
  a.stroke_m = actuators.PositiveDouble("stroke_m");
  a.force_limit_n = actuators.PositiveDouble("force_limit_n");

  a.viscous_friction_nspm = actuators.NonNegativeDouble("viscous_friction_nspm");
  a.force_lag_s = actuators.NonNegativeDouble("force_lag_s");
  a.endstop_stiffness_npm = actuators.PositiveDouble("endstop_stiffness_npm");
  a.endstop_damping_nspm = actuators.NonNegativeDouble("endstop_damping_nspm");
  return a;
}

}  // namespace stewart
