#pragma once
// The platform body's ten inertial parameters (model/inertial_regressor.h)
// fitted by weighted least squares to recorded motion and leg forces.
//
// qdd is not measured and differentiating the estimated qd twice amplifies
// its noise, so the fit uses the dynamics in momentum form, integrated over
// windows of `window_s` (an integral filter applied to both sides):
//
//   p(t_b) - p(t_a) + int_a^b r dt = int_a^b H (F - b H^T qd) dt
//
// with p = M qd and r = C qd + G - Mdot qd, each the platform body's part
// (Y_p pi, Y_r pi) plus the legs' (from the model). The state enters only at
// the window's ends (p) and under integrals; each window gives six rows. The
// legs, the geometry and the leg friction b stay the model's. Design and
// measured accuracy: docs/hardware.md, "Identify the platform and its payload".
#include <array>
#include <cstdint>
#include <vector>

#include "stewart/common/check.h"
#include "stewart/identify/identification_sample.h"
#include "stewart/model/inertial_regressor.h"
#include "stewart/model/platform_params.h"

namespace stewart::identify {

struct InertialFitOptions {
  double window_s = 0.25;  ///< integration window (s); see docs/hardware.md for the choice
  /// Samples further apart than this split the record (a dropped message):
  /// no window spans a gap.
  double max_sample_gap_s = 0.0025;
  /// Samples with a leg this close to a stroke end break the record too: the
  /// end-stop's force is not in the model (a platform heavier than the
  /// config's can sit on the end stops until the controller lifts it).
  double stroke_margin_m = 0.002;
  int min_windows = 20;  ///< fewer: an error (too little data for a fit)
  /// Larger (after scaling every column to unit norm): an error, the
  /// excitation does not determine every parameter.
  double max_condition_number = 1e5;
};

/// Thrown for data the fit cannot use: no or too few samples, non-finite or
/// unordered samples, a singular regressor. what() says which, in one line.
class IdentificationError : public InputError {
 public:
  explicit IdentificationError(const std::string& reason);
};

using InertialCovariance = Eigen::Matrix<double, kNumInertialParameters, kNumInertialParameters>;

struct InertialFit {
  InertialParameters pi = InertialParameters::Zero();  ///< model/inertial_regressor.h order
  /// Covariance of pi from the weighted residuals: s^2 (A^T W A)^-1 with
  /// s^2 = r^T W r / (rows - 10).
  InertialCovariance covariance = InertialCovariance::Zero();
  /// RMS residual per generalised coordinate over the windows: x, y, z in
  /// N s, phi, theta, psi in N m s (the rows' units: momentum change).
  Vector6d residual_rms = Vector6d::Zero();
  /// The same relative to the RMS of the right-hand side (the applied
  /// impulse) of each coordinate: how much of it the fit leaves unexplained.
  Vector6d relative_residual = Vector6d::Zero();
  double condition_number = 0.0;   ///< of the weighted, column-scaled regressor
  long samples = 0;                ///< samples given
  long samples_at_stroke_end = 0;  ///< of those, excluded (stroke_margin_m)
  long windows = 0;
  double duration_s = 0.0;  ///< time covered by the windows

  InertialParameters sigma() const { return covariance.diagonal().cwiseSqrt(); }
};

/// Names of pi's entries, for messages: "m", "m*c_x", ..., "I_O,zz".
extern const std::array<const char*, kNumInertialParameters> kInertialParameterNames;

/// Fits pi. `model` gives the geometry, the legs and gravity (its platform
/// body is ignored); `leg_friction_nspm` is actuators.viscous_friction_nspm.
/// Samples must be in time order. Throws IdentificationError.
InertialFit FitInertialParameters(const PlatformParams& model, double leg_friction_nspm,
                                  const std::vector<IdentificationSample>& samples,
                                  const InertialFitOptions& options = {});

}  // namespace stewart::identify
