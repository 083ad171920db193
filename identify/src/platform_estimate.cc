#include "stewart/identify/platform_estimate.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>

namespace stewart::identify {
namespace {

std::string Format(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

void CheckPhysical(const PlatformBody& body) {
  if (!(body.mass_kg > 0.0)) {
    throw IdentificationError("the fitted mass " + Format(body.mass_kg) +
                              " kg is not positive: not a physical body");
  }
  const Vector3d principal =
      Eigen::SelfAdjointEigenSolver<Matrix3d>(body.inertia_about_com_in_P_kgm2).eigenvalues();
  if (!(principal.minCoeff() > 0.0)) {
    throw IdentificationError(
        "the fitted inertia about the CoM is not positive definite "
        "(principal moments " +
        Format(principal(0)) + ", " + Format(principal(1)) + ", " + Format(principal(2)) +
        " kg m^2): not a physical body");
  }
  // Sorted ascending: the one inequality that can fail is the largest.
  if (principal(0) + principal(1) < principal(2)) {
    throw IdentificationError("the fitted principal moments " + Format(principal(0)) + ", " +
                              Format(principal(1)) + ", " + Format(principal(2)) +
                              " kg m^2 violate the triangle inequality of a rigid body");
  }
}

}  // namespace

PlatformValues PlatformValuesOf(const PlatformBody& body) {
  const Matrix3d& I = body.inertia_about_com_in_P_kgm2;
  PlatformValues v;
  v << body.mass_kg, body.com_in_P_m, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2);
  return v;
}

PlatformEstimate EstimatePlatform(const InertialFit& fit) {
  PlatformEstimate e;
  e.body = PlatformBodyOf(fit.pi);
  CheckPhysical(e.body);
  e.values = PlatformValuesOf(e.body);
  // d values / d pi by central differences (the conversion is smooth away
  // from m = 0, which the check above excludes), steps a small fraction of
  // each parameter's own uncertainty: the linearisation the sigma assumes.
  const InertialParameters sigma_pi = fit.sigma();
  Eigen::Matrix<double, 10, kNumInertialParameters> J;
  for (int j = 0; j < kNumInertialParameters; ++j) {
    const double h = 1e-3 * (sigma_pi(j) > 0.0 ? sigma_pi(j) : 1e-9 + std::abs(fit.pi(j)));
    InertialParameters plus = fit.pi, minus = fit.pi;
    plus(j) += h;
    minus(j) -= h;
    J.col(j) = (PlatformValuesOf(PlatformBodyOf(plus)) - PlatformValuesOf(PlatformBodyOf(minus))) /
               (2.0 * h);
  }
  e.sigma = (J * fit.covariance * J.transpose()).diagonal().cwiseSqrt();
  return e;
}

}  // namespace stewart::identify
