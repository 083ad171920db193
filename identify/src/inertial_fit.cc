#include "stewart/identify/inertial_fit.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "stewart/model/dynamics.h"

namespace stewart::identify {

const std::array<const char*, kNumInertialParameters> kInertialParameterNames = {
    "m", "m*c_x", "m*c_y", "m*c_z", "I_O,xx", "I_O,xy", "I_O,xz", "I_O,yy", "I_O,yz", "I_O,zz"};

IdentificationError::IdentificationError(const std::string& reason)
    : InputError("identification", reason, "identification: " + reason) {}

namespace {

// What one sample contributes: the platform body's momentum and remainder
// regressors, the legs' momentum and remainder, and H at its pose.
struct SampleTerms {
  InertialRegressor momentum;
  InertialRegressor remainder;
  LegMomentumTerms legs;
  Matrix6d H;
  Vector6d leg_length_m;
};

SampleTerms TermsAt(const PlatformParams& model, const IdentificationSample& s) {
  SampleTerms t;
  t.momentum = MomentumRegressor(s.q, s.qd);
  t.remainder = MomentumRemainderRegressor(model.gravity_mps2, s.q, s.qd);
  t.legs = LegMomentum(model, s.q, s.qd);
  const DynamicsTerms model_terms = EvaluateDynamics(model, s.q, s.qd);
  t.H = model_terms.H;
  t.leg_length_m = model_terms.leg_length_m;
  return t;
}

// The generalised force of the legs at a state: H (F - b H^T qd).
Vector6d LegForce(const Matrix6d& H, const Vector6d& force_n, double friction_nspm,
                  const Vector6d& qd) {
  return H * (force_n - friction_nspm * (H.transpose() * qd));
}

std::string Format(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

void CheckSamples(const std::vector<IdentificationSample>& samples) {
  if (samples.empty()) {
    throw IdentificationError("no samples (no state estimate paired with a safe command)");
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const IdentificationSample& s = samples[k];
    if (!s.q.allFinite() || !s.qd.allFinite() || !s.force_n.allFinite()) {
      throw IdentificationError("sample " + std::to_string(k) + " (utime " +
                                std::to_string(s.utime) + ") is not finite");
    }
    if (k > 0 && s.utime <= samples[k - 1].utime) {
      throw IdentificationError("samples are not in time order at sample " + std::to_string(k) +
                                " (utime " + std::to_string(s.utime) + ")");
    }
  }
}

// One window's six rows: A pi = y.
struct Window {
  InertialRegressor A = InertialRegressor::Zero();
  Vector6d y = Vector6d::Zero();
  double duration_s = 0.0;
};

// Windows of window_s, adjacent within each gap-free stretch of samples; a
// stretch's remainder shorter than a window is not used.
std::vector<Window> BuildWindows(const PlatformParams& model, double friction_nspm,
                                 const std::vector<IdentificationSample>& samples,
                                 const InertialFitOptions& options, long* samples_at_stroke_end) {
  std::vector<SampleTerms> terms;
  terms.reserve(samples.size());
  std::vector<bool> at_stroke_end;
  at_stroke_end.reserve(samples.size());
  for (const IdentificationSample& s : samples) {
    terms.push_back(TermsAt(model, s));
    const Vector6d& l = terms.back().leg_length_m;
    at_stroke_end.push_back((l.array() < model.leg_min_length_m + options.stroke_margin_m).any() ||
                            (l.array() > model.leg_max_length_m - options.stroke_margin_m).any());
    if (at_stroke_end.back()) ++*samples_at_stroke_end;
  }

  const auto window_us = static_cast<std::int64_t>(std::llround(options.window_s * 1e6));
  const auto max_gap_us = static_cast<std::int64_t>(std::llround(options.max_sample_gap_s * 1e6));
  std::vector<Window> windows;
  Window w;
  std::size_t start = 0;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
    const IdentificationSample& s0 = samples[k];
    const IdentificationSample& s1 = samples[k + 1];
    // A gap, or a sample on an end stop: the window restarts after it.
    if (s1.utime - s0.utime > max_gap_us || at_stroke_end[k] || at_stroke_end[k + 1]) {
      w = Window{};
      start = k + 1;
      continue;
    }
    // Trapezoidal integral over the interval; the command of sample k acts
    // over all of it, H and the friction follow the state at both ends.
    const double dt = static_cast<double>(s1.utime - s0.utime) * 1e-6;
    const SampleTerms& t0 = terms[k];
    const SampleTerms& t1 = terms[k + 1];
    w.A += 0.5 * dt * (t0.remainder + t1.remainder);
    w.y +=
        0.5 * dt *
        (LegForce(t0.H, s0.force_n, friction_nspm, s0.qd) +
         LegForce(t1.H, s0.force_n, friction_nspm, s1.qd) - t0.legs.remainder - t1.legs.remainder);
    if (s1.utime - samples[start].utime < window_us) continue;
    const SampleTerms& ta = terms[start];
    w.A += t1.momentum - ta.momentum;
    w.y -= t1.legs.momentum - ta.legs.momentum;
    w.duration_s = static_cast<double>(s1.utime - samples[start].utime) * 1e-6;
    windows.push_back(w);
    w = Window{};
    start = k + 1;
  }
  return windows;
}

// Least squares of the weighted rows, columns scaled to unit norm so the
// condition number compares the parameters' influence, not their units.
struct Solution {
  InertialParameters pi = InertialParameters::Zero();
  InertialCovariance inverse_normal = InertialCovariance::Zero();  // (A_w^T A_w)^-1
  double condition_number = INFINITY;
  // The right singular vector of the smallest singular value.
  InertialParameters weakest_direction = InertialParameters::Zero();
};

Solution Solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& y) {
  InertialParameters scale;
  for (int j = 0; j < kNumInertialParameters; ++j) {
    const double n = A.col(j).norm();
    scale(j) = n > 0.0 ? 1.0 / n : 1.0;
  }
  const Eigen::MatrixXd As = A * scale.asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(As, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  Solution s;
  const double smallest = sv(kNumInertialParameters - 1);
  s.condition_number = smallest > 0.0 ? sv(0) / smallest : INFINITY;
  s.weakest_direction = svd.matrixV().col(kNumInertialParameters - 1);
  if (!std::isfinite(s.condition_number)) return s;
  const Eigen::VectorXd inverse_sv = sv.cwiseInverse();
  s.pi = scale.asDiagonal() *
         (svd.matrixV() * (inverse_sv.asDiagonal() * (svd.matrixU().transpose() * y)));
  const Eigen::MatrixXd V_scaled = svd.matrixV() * inverse_sv.asDiagonal();
  s.inverse_normal = scale.asDiagonal() * (V_scaled * V_scaled.transpose()) * scale.asDiagonal();
  return s;
}

std::string WeakParameters(const InertialParameters& direction) {
  std::string names;
  for (int j = 0; j < kNumInertialParameters; ++j) {
    if (std::abs(direction(j)) < 0.3) continue;
    if (!names.empty()) names += ", ";
    names += kInertialParameterNames[static_cast<std::size_t>(j)];
  }
  return names;
}

// Per generalised coordinate: RMS of the residual of that row over the windows.
Vector6d RowRms(const Eigen::VectorXd& r) {
  Vector6d sum = Vector6d::Zero();
  const long windows = r.size() / 6;
  for (long i = 0; i < windows; ++i) sum += r.segment<6>(6 * i).cwiseAbs2();
  return (sum / static_cast<double>(windows)).cwiseSqrt();
}

}  // namespace

InertialFit FitInertialParameters(const PlatformParams& model, double leg_friction_nspm,
                                  const std::vector<IdentificationSample>& samples,
                                  const InertialFitOptions& options) {
  CheckSamples(samples);
  InertialFit fit;
  const std::vector<Window> windows =
      BuildWindows(model, leg_friction_nspm, samples, options, &fit.samples_at_stroke_end);
  fit.samples = static_cast<long>(samples.size());
  fit.windows = static_cast<long>(windows.size());
  for (const Window& w : windows) fit.duration_s += w.duration_s;
  // Six rows a window: two windows are the least that leave a residual.
  if (fit.windows < std::max(options.min_windows, 2)) {
    const double span_s = static_cast<double>(samples.back().utime - samples.front().utime) * 1e-6;
    throw IdentificationError(std::to_string(samples.size()) + " samples over " + Format(span_s) +
                              " s give " + std::to_string(fit.windows) + " windows of " +
                              Format(options.window_s) + " s without a sample gap (" +
                              std::to_string(fit.samples_at_stroke_end) +
                              " samples at a stroke end); at least " +
                              std::to_string(options.min_windows) + " are needed");
  }

  const long rows = 6 * fit.windows;
  Eigen::MatrixXd A(rows, kNumInertialParameters);
  Eigen::VectorXd y(rows);
  for (long i = 0; i < fit.windows; ++i) {
    A.middleRows<6>(6 * i) = windows[static_cast<std::size_t>(i)].A;
    y.segment<6>(6 * i) = windows[static_cast<std::size_t>(i)].y;
  }
  // The six coordinates' rows have different units and noise (N s against
  // N m s): a first, unweighted fit measures each one's residual, and the
  // second weighs every row by the inverse of its coordinate's.
  const Vector6d rhs_rms = RowRms(y);
  Vector6d weight = Vector6d::Ones();
  Eigen::VectorXd row_weight(rows);
  Solution solution;
  for (int pass = 0; pass < 2; ++pass) {
    if (pass > 0) {
      // A coordinate fitted exactly (noise-free data) keeps a finite weight.
      const Vector6d rms = RowRms(y - A * solution.pi);
      weight = (rms.array().max(1e-12 * rhs_rms.array()).max(1e-300)).inverse();
    }
    for (long i = 0; i < fit.windows; ++i) row_weight.segment<6>(6 * i) = weight;
    solution = Solve(row_weight.asDiagonal() * A, row_weight.asDiagonal() * y);
    if (!(solution.condition_number <= options.max_condition_number)) {
      throw IdentificationError(
          "the regressor is singular (condition number " + Format(solution.condition_number) +
          " > " + Format(options.max_condition_number) + "): the motion does not determine " +
          WeakParameters(solution.weakest_direction) + "; excite every rotation axis");
    }
  }
  const Eigen::VectorXd residual = y - A * solution.pi;
  const double s2 = (row_weight.asDiagonal() * residual).squaredNorm() /
                    static_cast<double>(rows - kNumInertialParameters);
  fit.pi = solution.pi;
  fit.covariance = s2 * solution.inverse_normal;
  fit.condition_number = solution.condition_number;
  fit.residual_rms = RowRms(residual);
  fit.relative_residual = fit.residual_rms.cwiseQuotient(rhs_rms.cwiseMax(1e-300));
  return fit;
}

}  // namespace stewart::identify
