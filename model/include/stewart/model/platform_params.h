#pragma once
// Physical parameters of the Stewart platform. Every value is SI; frames:
// {B} base frame (z up, origin at the centre of the base joint circle),
// {P} platform frame (origin at the centre of the platform joint circle).
#include "stewart/model/types.h"

namespace stewart {

/// One leg: a cylinder (motor and housing) hinged at the base by a universal
/// joint, and a rod sliding in it, attached to the platform by a spherical
/// joint. Both are modelled as axisymmetric bodies on the leg axis; their
/// inertia about the leg axis is neglected (see docs/model.md).
struct LegParams {
  double cylinder_mass_kg = 0.0;
  double cylinder_com_from_base_m = 0.0;  ///< along the leg axis, from b_i
  double cylinder_inertia_kgm2 = 0.0;     ///< transverse, about its CoM
  double rod_mass_kg = 0.0;
  double rod_com_from_platform_m = 0.0;  ///< along the leg axis, from p_i
  double rod_inertia_kgm2 = 0.0;         ///< transverse, about its CoM
  /// The actuator's rotor inertia seen along the leg axis (kg): kinetic
  /// energy 1/2 m_r Ld^2 (DcMotorParams::reflected_mass_kg; 0 for an ideal
  /// force source).
  double actuator_reflected_mass_kg = 0.0;
};

struct PlatformParams {
  /// Base joint centres b_i in {B} (m), one column per leg.
  Eigen::Matrix<double, 3, kNumLegs> base_joints_in_B_m;
  /// Platform joint centres p_i in {P} (m), one column per leg.
  Eigen::Matrix<double, 3, kNumLegs> platform_joints_in_P_m;

  double platform_mass_kg = 0.0;
  Vector3d platform_com_in_P_m = Vector3d::Zero();  ///< in {P}
  /// Inertia about the CoM, axes of {P} (kg m^2): diagonal Ixx, Iyy, Izz...
  Vector3d platform_inertia_kgm2 = Vector3d::Zero();
  /// ... and products Ixy, Ixz, Iyz (zero for the bare plate; a payload off
  /// the axes adds them).
  Vector3d platform_inertia_products_kgm2 = Vector3d::Zero();

  LegParams leg;

  /// Joint-to-joint leg length range of the actuators (m): the stroke ends.
  double leg_min_length_m = 0.0;
  double leg_max_length_m = 0.0;

  double gravity_mps2 = 9.81;  ///< acts along -z of {B}
};

/// The platform's inertia tensor about its CoM in {P} axes (kg m^2).
inline Matrix3d PlatformInertiaInP(const PlatformParams& p) {
  const Vector3d& d = p.platform_inertia_kgm2;
  const Vector3d& o = p.platform_inertia_products_kgm2;
  Matrix3d I;
  I << d(0), o(0), o(1), o(0), d(1), o(2), o(1), o(2), d(2);
  return I;
}

/// Joint centres on a circle of `radius_m`, in pairs: joint angles (deg)
/// measured from the x axis of the frame. Used to build the default geometry.
Eigen::Matrix<double, 3, kNumLegs> JointsOnCircle(double radius_m,
                                                  const std::array<double, kNumLegs>& angles_deg);

}  // namespace stewart
