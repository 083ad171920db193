#include "stewart/identify/actuator_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "stewart/identify/leg_path.h"
#include "stewart/identify/ramp_start.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/kinematics.h"

namespace stewart::identify {

const std::array<const char*, kNumMotorValues> kMotorValueNames = {
    "dead_band_duty",       "stall_force_n",    "no_load_speed_mps", "reflected_mass_kg",
    "force_at_full_duty_n", "leg_damping_nspm", "start_duty"};

namespace {

enum { kAlpha, kBeta, kGamma, kKappa, kNumTheta };

// Larger relative sigma of gamma: the fit refuses (see FitLeg).
constexpr double kMaxScaleSigma = 0.25;

std::string Fmt(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// The duty applied from t_s on (s, from the leg's first sample).
struct DutyEvent {
  double t_s = 0.0;
  double duty = 0.0;
};

// One excursion: the motor energised from events[0].t_s to t_off_s, the
// fit's samples [first, end) of the leg's arrays.
struct Segment {
  std::vector<DutyEvent> events;
  double t_off_s = 0.0;
  std::size_t first = 0;
  std::size_t end = 0;
  double start_load_n = 0.0;  // F_load and m_p at rest before it
  double start_inertia_kg = 0.0;
};

// A leg's record as the fit reads it.
struct LegData {
  std::vector<double> t_s;
  std::vector<double> length_m;
  std::vector<double> load_n;
  std::vector<double> inertia_kg;
  std::vector<Segment> segments;
  std::vector<std::size_t> rows;  // residual row -> sample index
};

std::string LegName(int leg) { return "leg " + std::to_string(leg); }

LegData Prepare(const PlatformParams& model, const LegTestRecord& rec, const Vector6d& pose_guess) {
  LegData d;
  const std::size_t n = rec.samples.size();
  if (n == 0) throw IdentificationError(LegName(rec.leg) + ": no samples");
  const int64_t t0 = rec.samples.front().utime;
  const auto seconds = [t0](int64_t utime) { return static_cast<double>(utime - t0) * 1e-6; };
  d.t_s.reserve(n);
  d.length_m.reserve(n);
  d.load_n.reserve(n);
  d.inertia_kg.reserve(n);
  Vector6d q = pose_guess;
  for (std::size_t k = 0; k < n; ++k) {
    const ActuatorSample& s = rec.samples[k];
    const ForwardKinematicsResult fk = ForwardKinematics(model, s.leg_length_m, q);
    if (!fk.converged) {
      throw IdentificationError(LegName(rec.leg) + ": no pose fits the leg readings at utime " +
                                std::to_string(s.utime) + " (forward kinematics, residual " +
                                Fmt("%.2g", fk.residual_m) + " m)");
    }
    q = fk.q;
    const LegPathTerms terms = LegPathTermsAt(model, q, rec.leg);
    d.t_s.push_back(seconds(s.utime));
    d.length_m.push_back(s.leg_length_m(rec.leg));
    d.load_n.push_back(terms.load_n);
    d.inertia_kg.push_back(terms.inertia_kg);
  }

  for (const ProcedureStep& step : rec.steps) {
    if (step.kind != StepKind::kExcursion) continue;
    const auto duty_at = [&](std::size_t k) { return rec.samples[k].applied_duty(rec.leg); };
    std::size_t k = step.first_sample;
    while (k < n && duty_at(k) == 0.0) ++k;
    if (k >= n || k >= step.end_sample + 5) {
      throw IdentificationError(LegName(rec.leg) + ": the device reports no duty applied during " +
                                "an excursion from utime " +
                                std::to_string(rec.samples[step.first_sample].utime));
    }
    if (k == 0) {
      throw IdentificationError(LegName(rec.leg) + ": an excursion starts at the first sample");
    }
    Segment seg;
    int64_t since = rec.samples[k].applied_since_utime;
    seg.events.push_back({seconds(since), duty_at(k)});
    bool ended = false;
    for (++k; k < n; ++k) {
      const ActuatorSample& s = rec.samples[k];
      // A new time with the same duty is no change (a device that reports
      // the latest frame's arrival): the change was at the earlier time.
      if (s.applied_since_utime == since || (duty_at(k) == duty_at(k - 1) && duty_at(k) != 0.0)) {
        continue;
      }
      since = s.applied_since_utime;
      if (duty_at(k) == 0.0) {
        seg.t_off_s = seconds(since);
        ended = true;
        break;
      }
      if (duty_at(k) * seg.events.front().duty < 0.0) {
        throw IdentificationError(LegName(rec.leg) + ": the applied duty reverses within an " +
                                  "excursion at utime " + std::to_string(s.utime));
      }
      seg.events.push_back({seconds(since), duty_at(k)});
    }
    if (!ended) seg.t_off_s = d.t_s.back();
    const double t_on = seg.events.front().t_s;
    // Samples strictly after the start, up to and including the switch-off
    // (the state there is still the energised motion's).
    std::size_t first = step.first_sample;
    while (first > 0 && d.t_s[first - 1] > t_on) --first;
    while (first < n && d.t_s[first] <= t_on) ++first;
    if (first == 0) throw IdentificationError(LegName(rec.leg) + ": no sample before an excursion");
    std::size_t end = first;
    while (end < n && d.t_s[end] <= seg.t_off_s) ++end;
    if (end - first < 20) continue;  // too short to say anything (a guard or a stop at once)
    seg.first = first;
    seg.end = end;
    seg.start_load_n = d.load_n[first - 1];
    seg.start_inertia_kg = d.inertia_kg[first - 1];
    d.segments.push_back(seg);
    for (std::size_t m = first; m < end; ++m) d.rows.push_back(m);
  }
  if (d.segments.empty()) {
    throw IdentificationError(LegName(rec.leg) + ": no excursion long enough to fit");
  }
  return d;
}

// The model's leg length at every fit row, for parameters theta and the
// segments' start lengths.
void Predict(const LegData& d, const LegModelParameters& theta, const Eigen::VectorXd& start_m,
             Eigen::VectorXd* predicted) {
  const double alpha = theta(kAlpha), beta = theta(kBeta), gamma = theta(kGamma),
               kappa = theta(kKappa);
  Eigen::Index row = 0;
  for (std::size_t j = 0; j < d.segments.size(); ++j) {
    const Segment& seg = d.segments[j];
    double length = start_m(static_cast<Eigen::Index>(j));
    double speed = 0.0;
    double t = seg.events.front().t_s;
    std::size_t ev = 0;
    double load = seg.start_load_n;
    double inertia = seg.start_inertia_kg;
    for (std::size_t m = seg.first; m < seg.end; ++m) {
      const double t_sample = d.t_s[m];
      while (t < t_sample) {
        const double t_next_event = ev + 1 < seg.events.size() ? seg.events[ev + 1].t_s : INFINITY;
        const double t_next = std::min(t_sample, t_next_event);
        const double h = t_next - t;
        const double duty = seg.events[ev].duty;
        const double u = alpha * duty - std::copysign(beta, duty) - gamma * load;
        const double tau = kappa + gamma * inertia;
        const double decay = std::exp(-h / tau);
        length += u * h + (speed - u) * tau * (1.0 - decay);
        speed = u + (speed - u) * decay;
        t = t_next;
        if (t >= t_next_event) ++ev;
      }
      (*predicted)(row++) = length;
      load = d.load_n[m];
      inertia = d.inertia_kg[m];
    }
  }
}

struct Solution {
  LegModelParameters theta;
  Eigen::VectorXd start_m;
  Eigen::VectorXd residual;
  Eigen::MatrixXd normal;  // J^T J at the solution
  int iterations = 0;
};

Eigen::VectorXd Residual(const LegData& d, const Eigen::VectorXd& measured,
                         const LegModelParameters& theta, const Eigen::VectorXd& start_m) {
  Eigen::VectorXd predicted(measured.size());
  Predict(d, theta, start_m, &predicted);
  return measured - predicted;
}

Solution Solve(const LegData& d, const LegModelParameters& theta0, int max_iterations, int leg) {
  const auto rows = static_cast<Eigen::Index>(d.rows.size());
  const auto segments = static_cast<Eigen::Index>(d.segments.size());
  const Eigen::Index p = kNumTheta + segments;
  Eigen::VectorXd measured(rows);
  for (Eigen::Index r = 0; r < rows; ++r)
    measured(r) = d.length_m[d.rows[static_cast<std::size_t>(r)]];
  Solution s;
  s.theta = theta0;
  s.start_m.resize(segments);
  for (Eigen::Index j = 0; j < segments; ++j) {
    s.start_m(j) = d.length_m[d.segments[static_cast<std::size_t>(j)].first - 1];
  }
  s.residual = Residual(d, measured, s.theta, s.start_m);
  double sse = s.residual.squaredNorm();
  double lambda = 1e-3;
  Eigen::MatrixXd J(rows, p);
  Eigen::VectorXd base(rows), shifted(rows);
  for (s.iterations = 0; s.iterations < max_iterations; ++s.iterations) {
    Predict(d, s.theta, s.start_m, &base);
    for (int i = 0; i < kNumTheta; ++i) {
      LegModelParameters t = s.theta;
      const double h = 1e-6 * std::max(std::abs(s.theta(i)), 1e-9);
      t(i) += h;
      Predict(d, t, s.start_m, &shifted);
      J.col(i) = (shifted - base) / h;
    }
    J.rightCols(segments).setZero();
    Eigen::Index row = 0;
    for (Eigen::Index j = 0; j < segments; ++j) {
      const Segment& seg = d.segments[static_cast<std::size_t>(j)];
      const auto count = static_cast<Eigen::Index>(seg.end - seg.first);
      J.col(kNumTheta + j).segment(row, count).setOnes();
      row += count;
    }
    s.normal = J.transpose() * J;
    const Eigen::VectorXd gradient = J.transpose() * s.residual;
    bool improved = false;
    for (int attempt = 0; attempt < 12 && !improved; ++attempt) {
      Eigen::MatrixXd damped = s.normal;
      damped.diagonal() += lambda * s.normal.diagonal();
      const Eigen::VectorXd step = damped.ldlt().solve(gradient);
      if (!step.allFinite()) break;
      LegModelParameters theta = s.theta + step.head<kNumTheta>();
      const Eigen::VectorXd start = s.start_m + step.tail(segments);
      // tau must stay positive for the model to mean anything.
      if (!(theta(kKappa) + theta(kGamma) * 1e-3 > 0.0) || !(theta(kGamma) > 0.0)) {
        lambda *= 10.0;
        continue;
      }
      const Eigen::VectorXd residual = Residual(d, measured, theta, start);
      const double new_sse = residual.squaredNorm();
      if (std::isfinite(new_sse) && new_sse <= sse) {
        const double relative_step =
            (step.head<kNumTheta>().array() / s.theta.array()).abs().maxCoeff();
        s.theta = theta;
        s.start_m = start;
        s.residual = residual;
        const double change = (sse - new_sse) / std::max(sse, 1e-300);
        sse = new_sse;
        lambda = std::max(lambda / 10.0, 1e-12);
        improved = true;
        if (relative_step < 1e-9 || change < 1e-14) return s;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) {
      // No step lowers the sum any more: at the minimum (to rounding), if
      // the last Jacobian is sound.
      if (s.normal.allFinite()) return s;
      break;
    }
  }
  if (s.iterations >= max_iterations) return s;  // converged slowly; the caller judges
  throw IdentificationError(LegName(leg) + ": the model does not fit the record (the fit " +
                            "diverged); is the motor a DC motor, energised above the start duty?");
}

// 1 + 2 sum of the residual's autocorrelation within the segments, up to the
// first lag where it is no longer positive.
double CorrelationInflation(const LegData& d, const Eigen::VectorXd& residual) {
  const double total = residual.squaredNorm();
  if (!(total > 0.0)) return 1.0;
  double sum = 0.0;
  for (Eigen::Index lag = 1; lag < 2000; ++lag) {
    double c = 0.0;
    Eigen::Index row = 0;
    for (const Segment& seg : d.segments) {
      const auto count = static_cast<Eigen::Index>(seg.end - seg.first);
      if (count > lag) {
        c += residual.segment(row, count - lag).dot(residual.segment(row + lag, count - lag));
      }
      row += count;
    }
    const double rho = c / total;
    if (rho <= 0.0) break;
    sum += rho;
  }
  return 1.0 + 2.0 * sum;
}

// Jacobian of the derived values in theta and F_c, by central differences.
struct ValueJacobian {
  Eigen::Matrix<double, kNumMotorValues, kNumTheta> theta;
  MotorVector coulomb;
};

ValueJacobian DerivedJacobian(const LegModelParameters& theta, const ActuatorConfig& config,
                              double coulomb_n) {
  ValueJacobian j;
  for (int i = 0; i < kNumTheta; ++i) {
    const double h = 1e-6 * std::abs(theta(i)) + 1e-12;
    LegModelParameters plus = theta, minus = theta;
    plus(i) += h;
    minus(i) -= h;
    j.theta.col(i) =
        (MotorValuesOf(plus, config, coulomb_n) - MotorValuesOf(minus, config, coulomb_n)) /
        (2.0 * h);
  }
  const double h = 1e-3;
  j.coulomb =
      (MotorValuesOf(theta, config, coulomb_n + h) - MotorValuesOf(theta, config, coulomb_n - h)) /
      (2.0 * h);
  return j;
}

LegModelParameters StartingPoint(const ActuatorConfig& config, double coulomb_n) {
  const DcMotorParams& m = config.motor;
  const double b = ModelLegDampingNspm(config);
  const double a = DcMotorForceAtFullDuty(m) / (1.0 - m.dead_band_duty);
  LegModelParameters theta;
  theta << a / b, (a * m.dead_band_duty + coulomb_n) / b, 1.0 / b,
      std::max(m.reflected_mass_kg, 1.0) / b;
  return theta;
}

LegFit FitLeg(const PlatformParams& model, const ActuatorConfig& config, const LegTestRecord& rec,
              const ActuatorFitOptions& options) {
  Vector6d guess = Vector6d::Zero();
  guess(2) = rec.samples.empty() ? 0.0 : rec.samples.front().leg_length_m.mean();
  const LegData d = Prepare(model, rec, guess);
  const Solution s =
      Solve(d, StartingPoint(config, options.coulomb_friction_n), options.max_iterations, rec.leg);
  LegFit fit;
  fit.leg = rec.leg;
  fit.theta = s.theta;
  fit.samples = static_cast<long>(d.rows.size());
  fit.excursions = static_cast<int>(d.segments.size());
  fit.iterations = s.iterations;
  const auto rows = static_cast<double>(d.rows.size());
  const auto p = static_cast<double>(kNumTheta + d.segments.size());
  fit.residual_rms_m = std::sqrt(s.residual.squaredNorm() / rows);
  fit.correlation_inflation = CorrelationInflation(d, s.residual);
  const Eigen::MatrixXd inverse =
      s.normal.ldlt().solve(Eigen::MatrixXd::Identity(s.normal.rows(), s.normal.cols()));
  if (!inverse.allFinite()) {
    throw IdentificationError(LegName(rec.leg) + ": the excursions do not determine the model " +
                              "(singular fit)");
  }
  const double s2 = s.residual.squaredNorm() / std::max(rows - p, 1.0);
  fit.covariance = s2 * fit.correlation_inflation * inverse.topLeftCorner<kNumTheta, kNumTheta>();
  double load_sum = 0.0;
  for (const std::size_t m : d.rows) load_sum += d.load_n[m];
  fit.mean_load_n = load_sum / rows;

  if (!(fit.theta(kAlpha) > 0.0) || !(fit.theta(kGamma) > 0.0)) {
    throw IdentificationError(LegName(rec.leg) + ": unphysical fit (the leg's speed does not " +
                              "grow with the duty, or its damping is not positive)");
  }
  // The absolute force scale rests on the leg's load alone: without enough
  // of it gamma (1 / b) is not determined, and every force with it.
  const double gamma_relative_sigma = std::sqrt(fit.covariance(kGamma, kGamma)) / fit.theta(kGamma);
  if (!(gamma_relative_sigma < kMaxScaleSigma)) {
    throw IdentificationError(
        LegName(rec.leg) + ": the force scale is not determined (leg damping +- " +
        Fmt("%.0f", 100.0 * gamma_relative_sigma) + " %): the leg's load from the platform's " +
        "weight, " + Fmt("%.3g", fit.mean_load_n) + " N, is too small against the pot's noise " +
        "to tell extending from retracting speeds (--repeats, or a known mass on the platform)");
  }
  // The ramps: where the leg started, and where the line says it should.
  std::size_t ramp_index = 0;
  for (std::size_t k = 1; k < rec.steps.size(); ++k) {
    const ProcedureStep& step = rec.steps[k];
    if (step.kind != StepKind::kRamp || ramp_index >= 2) continue;
    const ProcedureStep& rest = rec.steps[k - 1];
    const std::size_t from = rest.first_sample + (rest.end_sample - rest.first_sample) / 2;
    double sum = 0.0;
    for (std::size_t m = from; m < rest.end_sample; ++m) sum += d.length_m[m];
    const double reference = sum / static_cast<double>(rest.end_sample - from);
    const std::size_t i = step.sign > 0 ? 0 : 1;
    fit.ramp_start_duty[i] = RampStartDuty(rec, step, reference, step.ramp_rate_per_s).duty;
    const double load = d.load_n[step.first_sample];
    fit.line_start_duty[i] =
        (fit.theta(kBeta) + step.sign * fit.theta(kGamma) * load) / fit.theta(kAlpha);
    ++ramp_index;
  }

  fit.values = MotorValuesOf(fit.theta, config, options.coulomb_friction_n);
  const ValueJacobian jac = DerivedJacobian(fit.theta, config, options.coulomb_friction_n);
  fit.sigma_fit = (jac.theta * fit.covariance * jac.theta.transpose()).diagonal().cwiseSqrt();
  fit.sigma_prior = jac.coulomb.cwiseAbs() * options.coulomb_friction_sigma_n;
  if (!(fit.values(kLegDampingNspm) > config.viscous_friction_nspm) ||
      !(fit.values(kReflectedMassKg) >= 0.0) || !(fit.values(kForceAtFullDutyN) > 0.0)) {
    throw IdentificationError(
        LegName(rec.leg) + ": unphysical fit: leg damping " +
        Fmt("%.4g", fit.values(kLegDampingNspm)) + " N s/m (the screw alone has " +
        Fmt("%.4g", config.viscous_friction_nspm) + "), rotor mass " +
        Fmt("%.4g", fit.values(kReflectedMassKg)) + " kg, force at full duty " +
        Fmt("%.4g", fit.values(kForceAtFullDutyN)) + " N");
  }
  return fit;
}

}  // namespace

MotorVector MotorValuesOf(const LegModelParameters& theta, const ActuatorConfig& config,
                          double coulomb_friction_n) {
  const DcMotorParams& m = config.motor;
  const double b = 1.0 / theta(kGamma);
  const double a = theta(kAlpha) * b;
  const double offset = theta(kBeta) * b;
  MotorVector v;
  v(kDeadBandDuty) = (offset - coulomb_friction_n) / a;
  v(kForceAtFullDutyN) = a * (1.0 - v(kDeadBandDuty));
  v(kStallForceN) =
      v(kForceAtFullDutyN) * m.rated_voltage_v / (m.supply_voltage_v - m.bridge_drop_v);
  v(kLegDampingNspm) = b;
  v(kNoLoadSpeedMps) = v(kStallForceN) / (b - config.viscous_friction_nspm);
  v(kReflectedMassKg) = theta(kKappa) * b;
  v(kStartDuty) = theta(kBeta) / theta(kAlpha);
  return v;
}

ActuatorFit FitActuators(const PlatformParams& model, const ActuatorConfig& config,
                         const ActuatorRecord& record, const ActuatorFitOptions& options) {
  if (record.legs.empty()) throw IdentificationError("no leg was tested");
  ActuatorFit fit;
  for (const LegTestRecord& rec : record.legs) {
    fit.legs.push_back(FitLeg(model, config, rec, options));
    fit.samples += fit.legs.back().samples;
  }
  fit.duration_s = record.duration_s;
  const auto n = static_cast<double>(fit.legs.size());
  for (int v = 0; v < kNumMotorValues; ++v) {
    double weights = 0.0, weighted = 0.0, prior = 0.0;
    for (const LegFit& leg : fit.legs) {
      const double w = 1.0 / std::max(leg.sigma_fit(v) * leg.sigma_fit(v), 1e-300);
      weights += w;
      weighted += w * leg.values(v);
      prior += leg.sigma_prior(v) / n;
    }
    const double mean = weighted / weights;
    double chi2 = 0.0;
    for (const LegFit& leg : fit.legs) {
      const double e = (leg.values(v) - mean) / std::max(leg.sigma_fit(v), 1e-300);
      chi2 += e * e;
    }
    fit.values(v) = mean;
    fit.leg_spread(v) = n > 1.0 ? chi2 / (n - 1.0) : 0.0;
    fit.sigma_fit(v) = std::sqrt(1.0 / weights) * std::sqrt(std::max(1.0, fit.leg_spread(v)));
    fit.sigma_prior(v) = prior;
    fit.sigma(v) = std::hypot(fit.sigma_fit(v), fit.sigma_prior(v));
  }
  return fit;
}

}  // namespace stewart::identify
