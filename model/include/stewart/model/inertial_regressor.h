#pragma once
// The platform dynamics are linear in the platform body's inertial
// parameters (docs/model.md, "Inertial regressor"): with pi the ten standard
// parameters below,
//
//   M(q) qdd + C(q, qd) qd + G(q) = Y(q, qd, qdd) pi + (the legs' part),
//
// the legs' part being the model's own (EvaluateDynamics with the platform
// body massless). Identification (identify/) fits pi from recorded motion.
//
// Because qdd is not measured, the fit uses the momentum form of the same
// equation: with p = M qd the generalised momentum,
//
//   M qdd + C qd + G = dp/dt + r(q, qd),   r = C qd + G - Mdot qd,
//
// and both p and r are linear in pi with no qdd (MomentumRegressor,
// MomentumRemainderRegressor); integrated over a time window the derivative
// becomes a difference of momenta.
#include <Eigen/Core>

#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart {

constexpr int kNumInertialParameters = 10;

/// pi = [m, m c_x, m c_y, m c_z, Ixx, Ixy, Ixz, Iyy, Iyz, Izz]: mass (kg),
/// first moments (kg m, CoM c in {P}), and the inertia tensor about the
/// ORIGIN of {P} in {P} axes (kg m^2; the tensor's entries, so Ixy is the
/// (0, 1) entry, as in PlatformInertiaInP). About the origin, not the CoM:
/// only then is the dynamics linear in pi.
using InertialParameters = Eigen::Matrix<double, kNumInertialParameters, 1>;
/// Maps pi to six generalised forces (N, N m) or momenta (N s, N m s).
using InertialRegressor = Eigen::Matrix<double, 6, kNumInertialParameters>;

/// The platform body's pi from the config's values (mass, CoM, inertia about
/// the CoM incl. products), by the parallel-axis theorem.
InertialParameters InertialParametersOf(const PlatformParams& params);

/// The platform body's mass, CoM and inertia about the CoM, from pi.
struct PlatformBody {
  double mass_kg = 0.0;
  Vector3d com_in_P_m = Vector3d::Zero();
  Matrix3d inertia_about_com_in_P_kgm2 = Matrix3d::Zero();  ///< {P} axes
};
/// Inverse of InertialParametersOf; mass_kg must be non-zero (the CoM is
/// m c / m). Says nothing about physical consistency (see identify/).
PlatformBody PlatformBodyOf(const InertialParameters& pi);

/// `params` with its platform body replaced by `body` (legs, geometry,
/// gravity kept).
PlatformParams WithPlatformBody(const PlatformParams& params, const PlatformBody& body);

/// Y(q, qd, qdd): Y pi = the platform body's part of M qdd + C qd + G.
InertialRegressor PlatformInertialRegressor(double gravity_mps2, const Vector6d& q,
                                            const Vector6d& qd, const Vector6d& qdd);

/// Y_p(q, qd): Y_p pi = the platform body's part of the generalised momentum M qd.
InertialRegressor MomentumRegressor(const Vector6d& q, const Vector6d& qd);

/// Y_r(q, qd): Y_r pi = the platform body's part of r = C qd + G - Mdot qd,
/// so that Y(q, qd, qdd) pi = d/dt (Y_p pi) + Y_r pi along any motion.
InertialRegressor MomentumRemainderRegressor(double gravity_mps2, const Vector6d& q,
                                             const Vector6d& qd);

/// The legs' parts of the same terms, from the model (EvaluateDynamics with a
/// massless platform body): the legs are not identified.
struct LegMomentumTerms {
  Vector6d momentum;   ///< M_legs qd (N s, N m s)
  Vector6d remainder;  ///< C_legs qd + G_legs - Mdot_legs qd (N, N m)
};
/// Mdot_legs qd is the derivative of the model's M along qd, by a central
/// difference over +-`step_s` of motion at constant qd (q +- step_s qd):
/// a derivative of the model, which is smooth, not of measured data. The
/// default step keeps the error near 1e-9 relative at the platform's speeds.
LegMomentumTerms LegMomentum(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                             double step_s = 1e-4);

/// M_legs qdd + C_legs qd + G_legs (N, N m): the legs' part of the dynamics.
Vector6d LegDynamicsForce(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                          const Vector6d& qdd);

}  // namespace stewart
