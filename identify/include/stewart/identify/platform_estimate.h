#pragma once
// A fit of pi turned into the config's values (platform.mass_kg, com_m,
// inertia_kgm2, inertia_products_kgm2), each with its one-sigma uncertainty,
// after the physical-consistency checks.
#include "stewart/identify/inertial_fit.h"
#include "stewart/model/inertial_regressor.h"

namespace stewart::identify {

/// The config's ten values in this order: mass (kg), CoM in {P} (m, 3),
/// inertia about the CoM in {P} axes: diagonal Ixx, Iyy, Izz, then the
/// products Ixy, Ixz, Iyz (kg m^2; the tensor's entries, PlatformInertiaInP).
using PlatformValues = Eigen::Matrix<double, 10, 1>;

struct PlatformEstimate {
  PlatformBody body;
  PlatformValues values = PlatformValues::Zero();
  /// One sigma of each value, propagated from the fit's covariance through
  /// the (linearised) conversion from pi.
  PlatformValues sigma = PlatformValues::Zero();
};

PlatformValues PlatformValuesOf(const PlatformBody& body);

/// Converts and checks: mass > 0, the inertia about the CoM positive definite
/// with principal moments obeying the triangle inequality (a rigid body's;
/// the config loader demands it). Throws IdentificationError naming what is
/// not physical.
PlatformEstimate EstimatePlatform(const InertialFit& fit);

}  // namespace stewart::identify
