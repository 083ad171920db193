#pragma once
// The DC-motor legs' parameters from the records of the actuator procedure
// (actuator_procedure.h; design, identifiability and measured accuracy:
// docs/hardware.md, "Identify the actuators").
//
// Per leg, with the other legs held (leg_path.h) and the motor energised
// (every excursion level lies well above the start duty), the model's leg
// (model/dc_motor.h) obeys
//
//   (m_r + m_p) Ldd = A d - B sgn(d) - b Ld - F_load(q),
//   A = F_full / (1 - d0),   B = A d0 + F_c,   b = F_stall / v_noload + b_screw,
//
// F_full the drive force at full duty, d0 the dead band, F_c the dry
// friction while driven. Divided by b it is a first-order lag of the speed,
//
//   tau Ldd + Ld = alpha d - beta sgn(d) - gamma F_load(q),
//   alpha = A / b,  beta = B / b,  gamma = 1 / b,  tau = kappa + gamma m_p,  kappa = m_r / b,
//
// whose four parameters motion determines: alpha and beta from the speeds at
// the levels, kappa from the transients between them, and gamma -- the
// absolute force scale -- from the leg's known load F_load, which slows the
// leg when it lifts the platform and speeds it when it lowers it. The fit is
// an output-error fit: the model integrated exactly over each excursion
// (piecewise constant duty at the times the device applied it, F_load and m_p
// at each sample's pose by forward kinematics), started at rest at an unknown
// length, against the pot readings; Levenberg-Marquardt over the four
// parameters and one start length per excursion.
//
// Not identifiable from motion: d0 and F_c apart (only B = A d0 + F_c, the
// offset a moving leg's drive must overcome). The fit takes F_c as the
// config says (prior with its own uncertainty) and gives d0 = (B - F_c) / A
// and F_full = A (1 - d0); the uncertainty of the prior enters theirs.
// back_drive_force_n (no load near it) and lock_stiffness_npm (no motion
// while held) neither.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "stewart/identify/actuator_procedure.h"
#include "stewart/model/actuator_params.h"
#include "stewart/model/platform_params.h"

namespace stewart::identify {

/// The values the stack's config takes (actuators.motor) and what they come
/// from, in this order.
enum MotorValue {
  kDeadBandDuty,      ///< d0 = (B - F_c) / A
  kStallForceN,       ///< F_full V_rated / (V_supply - V_drop)
  kNoLoadSpeedMps,    ///< F_stall / (b - b_screw)
  kReflectedMassKg,   ///< m_r
  kForceAtFullDutyN,  ///< F_full = A (1 - d0)
  kLegDampingNspm,    ///< b, the whole leg damping (back-EMF and screw)
  kStartDuty,         ///< B / A: the duty a moving, unloaded leg needs (d0 and F_c together)
  kNumMotorValues
};
using MotorVector = Eigen::Matrix<double, kNumMotorValues, 1>;
extern const std::array<const char*, kNumMotorValues> kMotorValueNames;

/// The model's parameters: alpha (m/s per duty), beta (m/s), gamma (m/s per
/// N), kappa (s).
using LegModelParameters = Eigen::Vector4d;

struct ActuatorFitOptions {
  /// F_c the fit assumes (not identifiable: see above), and its one sigma.
  double coulomb_friction_n = 0.0;
  double coulomb_friction_sigma_n = 0.0;
  int max_iterations = 60;
};

struct LegFit {
  int leg = 0;
  LegModelParameters theta = LegModelParameters::Zero();
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  long samples = 0;  ///< in the fit (excursions)
  int excursions = 0;
  int iterations = 0;
  double residual_rms_m = 0.0;
  /// The covariance is s^2 (J^T J)^-1 times this: 1 + 2 sum of the
  /// residuals' autocorrelation (the quantised pot's errors are correlated
  /// while a slow leg crosses one ADC step).
  double correlation_inflation = 1.0;
  double mean_load_n = 0.0;  ///< F_load over the excursions
  /// From the ramps (ramp_start.h): the duty at which the leg started to
  /// move extending and retracting, and the duty at which the fitted speed
  /// line gives zero speed there (beta +- gamma F_load) / alpha. The ramp's
  /// is higher where static friction exceeds F_c.
  double ramp_start_duty[2] = {0.0, 0.0};
  double line_start_duty[2] = {0.0, 0.0};
  MotorVector values = MotorVector::Zero();
  MotorVector sigma_fit = MotorVector::Zero();    ///< from the fit's covariance
  MotorVector sigma_prior = MotorVector::Zero();  ///< from F_c's
};

struct ActuatorFit {
  std::vector<LegFit> legs;
  /// Inverse-variance weighted means over the legs.
  MotorVector values = MotorVector::Zero();
  /// sigma_fit of the mean, scaled by sqrt(chi^2 / (n - 1)) when the legs
  /// differ by more than their own sigmas; sigma_prior is common to all
  /// legs and does not average out; sigma is both in quadrature.
  MotorVector sigma_fit = MotorVector::Zero();
  MotorVector sigma_prior = MotorVector::Zero();
  MotorVector sigma = MotorVector::Zero();
  /// chi^2 / (n - 1) of the legs' values about the mean (0 for one leg).
  MotorVector leg_spread = MotorVector::Zero();
  long samples = 0;
  double duration_s = 0.0;
};

/// The derived values of one leg's parameters (the constants: the config's
/// supply, bridge drop, rated voltage, screw friction; F_c as given).
MotorVector MotorValuesOf(const LegModelParameters& theta, const ActuatorConfig& config,
                          double coulomb_friction_n);

/// Fits every leg of `record`. `model` is the config's platform (geometry,
/// bodies, gravity: F_load and m_p), `config` the config's actuators (the
/// constants above and the fit's starting point). Throws
/// IdentificationError: no excursions, a leg whose record the model cannot
/// follow (no convergence, a singular fit), an unphysical result (b, A, m_r
/// not positive).
ActuatorFit FitActuators(const PlatformParams& model, const ActuatorConfig& config,
                         const ActuatorRecord& record, const ActuatorFitOptions& options);

}  // namespace stewart::identify
