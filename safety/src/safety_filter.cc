#include "stewart/safety/safety_filter.h"

#include <Eigen/QR>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "stewart/common/check.h"
#include "stewart/model/linear_algebra6.h"
#include "stewart/safety/least_relaxation.h"
#include "stewart/safety/nominal_bound.h"
#include "stewart/safety/pose_plausibility.h"

namespace stewart::safety {
namespace {

// x - x is 0 for a finite x and NaN for NaN or +-Inf, and a NaN survives a
// sum: one comparison for all 96 numbers instead of a branch per entry.
bool StateAndTermsFinite(const Vector6d& q, const Vector6d& qd, const DynamicsTerms& t) {
  const double probe = (q - q).sum() + (qd - qd).sum() + (t.M - t.M).sum() + (t.H - t.H).sum() +
                       (t.C_qd - t.C_qd).sum() + (t.G - t.G).sum() +
                       (t.leg_length_m - t.leg_length_m).sum();
  return probe == 0.0;
}

bool BarriersFinite(const BarrierEvaluation& b) {
  const double probe = (b.psi_p - b.psi_p) + (b.psi_v - b.psi_v) + (b.h_pos - b.h_pos) +
                       (b.h_vel - b.h_vel) + (b.g_p - b.g_p).sum() + (b.g_v - b.g_v).sum();
  return probe == 0.0;
}

// The two conditions in the metric's coordinates y = T^-1 F: g~ = T^T g.
TwoConstraintProblem MakeProblem(const ConstraintSet& c, const BarrierEvaluation& b,
                                 const Matrix6d& map, CorrectionMetric metric) {
  TwoConstraintProblem p;
  p.psi_p = b.psi_p;
  p.psi_v = b.psi_v;
  if (metric == CorrectionMetric::kForce) {
    p.g_p = b.g_p;
    p.g_v = b.g_v;
  } else {
    p.g_p.noalias() = map.transpose() * b.g_p;
    p.g_v.noalias() = map.transpose() * b.g_v;
  }
  p.has_p = c.num_position > 0 && !b.outside_position_set;
  p.has_v = c.num_velocity > 0;
  return p;
}

// Solves H X = B in place with H's factor, factored by the first solve that
// needs it; false when H is singular or so nearly singular that the solve
// amplifies B by more than kMaxLegJacobianCondition (||H|| ||X|| / ||B|| <=
// cond(H)). Costs two norms on the steps that solve.
template <int Cols>
bool SolveWithLegJacobian(const Matrix6d& h, LegJacobianFactor* factor,
                          Eigen::Matrix<double, 6, Cols>* b) {
  const double rhs_norm = b->norm();
  if (!factor->Solve(h, b)) return false;
  return factor->h_norm() * b->norm() <= kMaxLegJacobianCondition * rhs_norm;
}

// T = H^-1 L_M given L_M; false (T NaN) when H is singular.
bool AccelerationMetricMap(const Matrix6d& h, const Matrix6d& l_m, LegJacobianFactor* factor,
                           Matrix6d* map) {
  *map = l_m;
  if (SolveWithLegJacobian(h, factor, map)) return true;
  map->setConstant(NAN);
  return false;
}

const Vector6d kNoDisturbance = Vector6d::Zero();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

FilterCase CaseFromMultipliers(double mu_p, double mu_v) {
  if (mu_p > 0.0 && mu_v > 0.0) return FilterCase::kBoth;
  if (mu_p > 0.0) return FilterCase::kPosition;
  if (mu_v > 0.0) return FilterCase::kVelocity;
  return FilterCase::kNone;
}

}  // namespace

SafetyFilter::SafetyFilter(const PlatformParams& platform, const SafetyConfig& safety,
                           const ActuatorConfig& actuators, ReferenceQpSolver* reference)
    : platform_(platform),
      constraints_(BuildConstraintSet(platform, safety)),
      variant_(safety.variant),
      metric_(safety.correction_metric),
      leg_friction_nspm_(safety.leg_friction_nspm),
      force_limits_(safety.force_limits_enabled),
      force_limit_n_(actuators.force_limit_n),
      fallback_(safety.fallback),
      stop_time_s_(safety.stop_time_s),
      drive_on_response_s_(safety.drive_on_response_s),
      use_disturbance_(safety.use_disturbance_estimate),
      check_each_barrier_(safety.check_each_barrier),
      nominal_max_accel_(NominalAccelerationBound(safety.sample_period_s,
                                                  safety.per_period_velocity_step_mps,
                                                  safety.per_period_angular_step_radps)),
      bound_nominal_((nominal_max_accel_.array() < kInfinity).any()),
      reference_(reference) {
  STEWART_CHECK_INPUT(safety.sample_period_s >= 0.0, "safety.sample_period_s", "must be >= 0");
  STEWART_CHECK_INPUT(safety.per_period_velocity_step_mps >= 0.0,
                      "safety.per_period_velocity_step_mps", "must be >= 0");
  STEWART_CHECK_INPUT(safety.per_period_angular_step_radps >= 0.0,
                      "safety.per_period_angular_step_radps", "must be >= 0");
  STEWART_CHECK_INPUT(force_limit_n_ > 0.0 || !force_limits_, "actuators.force_limit_n",
                      "must be positive when safety.force_limits_enabled");
  STEWART_CHECK_INPUT(stop_time_s_ > 0.0, "safety.stop_time_s", "must be positive");
  STEWART_CHECK_INPUT(drive_on_response_s_ >= 0.0, "safety.drive_on_response_s", "must be >= 0");
  STEWART_CHECK_INPUT(leg_friction_nspm_ >= 0.0, "safety.leg_friction_nspm", "must be >= 0");
  set_variant(variant_);
}

void SafetyFilter::set_variant(SafetyVariant variant) {
  STEWART_CHECK_INPUT(variant != SafetyVariant::kQpReference || reference_ != nullptr,
                      "safety.variant", "'qp' needs a reference QP solver");
  variant_ = variant;
}

void SafetyFilter::ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared) {
  shared_terms_ = AttachSharedTerms(platform_, std::move(shared));
}

Vector6d SafetyFilter::Step(const Vector6d& q, const Vector6d& qd, const Vector6d& f_des,
                            SafetyDiagnostics* diagnostics) {
  return Step(q, qd, f_des, GeneralizedDisturbance{}, diagnostics);
}

Vector6d SafetyFilter::Step(const Vector6d& q, const Vector6d& qd, const Vector6d& f_des,
                            const GeneralizedDisturbance& disturbance,
                            SafetyDiagnostics* diagnostics) {
  // The one clock read pair of a step: compute_ns covers the model terms and
  // the filter (StepWithTerms is not timed).
  const auto start = std::chrono::steady_clock::now();
  DynamicsTerms& terms = workspace_.terms;
  if (q.allFinite() && qd.allFinite()) {
    EvaluateDynamics(platform_, shared_terms_.get(), q, qd, &terms);
  } else {
    terms.M.setConstant(NAN);  // marks the terms invalid for StepWithTerms
  }
  const Vector6d f_safe = StepWithTerms(terms, q, qd, f_des, disturbance, diagnostics);
  diagnostics->compute_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start)
          .count();
  return f_safe;
}

Vector6d SafetyFilter::StepWithTerms(const DynamicsTerms& terms, const Vector6d& q,
                                     const Vector6d& qd, const Vector6d& f_des,
                                     SafetyDiagnostics* d) const {
  return StepWithTerms(terms, q, qd, f_des, GeneralizedDisturbance{}, d);
}

Vector6d SafetyFilter::StepWithTerms(const DynamicsTerms& terms, const Vector6d& q,
                                     const Vector6d& qd, const Vector6d& f_des,
                                     const GeneralizedDisturbance& disturbance,
                                     SafetyDiagnostics* d) const {
  d->variant = variant_;
  d->flags = 0;
  d->infeasible = false;
  d->mu_p = d->mu_v = 0.0;
  d->mu_position.fill(0.0);
  d->mu_velocity.fill(0.0);
  d->mu_force.setZero();
  d->f_des = f_des;
  d->compute_ns = 0;
  workspace_.leg_jacobian_degenerate = false;
  workspace_.leg_jacobian.Reset();
  workspace_.metric_factor_ready = false;
  workspace_.y_des_ready = false;

  // A finite pose the platform cannot be in (pose_plausibility.h) is as
  // invalid as a NaN: its model terms are numbers without meaning.
  const bool state_valid = StateAndTermsFinite(q, qd, terms) &&
                           PoseProblems(platform_, q, terms.leg_length_m) == kPosePlausible;
  // NaN compares false: this also rejects non-finite entries.
  // A non-finite disturbance estimate is an invalid state, like a NaN in q.
  const bool disturbance_valid =
      !use_disturbance_ || (disturbance.force_n.allFinite() && disturbance.std_n.allFinite() &&
                            (disturbance.std_n.array() >= 0.0).all());
  const bool input_valid =
      state_valid && disturbance_valid && (f_des.array().abs() <= kMaxInputForceN).all();
  bool ok = input_valid;
  FilterWorkspace& ws = workspace_;
  const Vector6d& held_disturbance =
      use_disturbance_ && disturbance_valid ? disturbance.force_n : kNoDisturbance;
  // The conditions are solved for the nominal within the per-period bound
  // (nominal_bound.h); correction and flags still compare with F_des.
  d->nominal_scale = 1.0;
  Vector6d& f_nominal = d->f_nominal;
  f_nominal = f_des;
  if (ok) PrepareBarrierIntermediates(terms, qd, &ws.barrier);
  if (ok && bound_nominal_) {
    const double scale = ws.barrier.inertia_valid
                             ? BoundNominal(terms, ws.barrier.inertia, &ws.leg_jacobian,
                                            ws.barrier.leg_rate, leg_friction_nspm_,
                                            held_disturbance, nominal_max_accel_, f_des, &f_nominal)
                             : 0.0;
    ok = scale > 0.0;
    if (scale < 1.0) {
      d->nominal_scale = scale;
      d->flags |= kFlagNominalBounded;
    }
  }
  const StepInput in{terms, qd, f_nominal, d->barriers, held_disturbance};
  if (ok) {
    EvaluatePreparedBarriers(constraints_, q, qd, terms, f_nominal, leg_friction_nspm_,
                             use_disturbance_ ? disturbance : GeneralizedDisturbance{},
                             &d->barriers, &ws.barrier);
    ok = BarriersFinite(d->barriers) &&
         (metric_ == CorrectionMetric::kForce || ws.barrier.inertia_valid);
  }
  bool solved = false;
  if (ok && force_limits_ && variant_ == SafetyVariant::kClosedForm) {
    // The box only matters when it cuts the unlimited optimum off: a convex
    // QP's optimum that satisfies constraints left out is the optimum with
    // them. The closed form (~0.3 us) first; the active set (~1.5 us) only
    // when F* leaves the box.
    SolveUnlimited(in, ws, d);
    solved = !d->infeasible && (d->f_safe.array().abs() <= force_limit_n_).all();
    if (!solved) {
      d->infeasible = false;
      d->mu_p = d->mu_v = 0.0;
    }
  }
  bool metric_map_ready = false;
  if (ok && !solved) {
    if (variant_ == SafetyVariant::kQpReference || variant_ == SafetyVariant::kUncomposed ||
        force_limits_) {
      // These pose the QP in y = T^-1 F, so they need T itself.
      ok = ComputeStepMetricMap(terms, &ws);
      metric_map_ready = ok;
      if (ok && variant_ == SafetyVariant::kQpReference) {
        SolveReference(in, &ws, d);
      } else if (ok && variant_ == SafetyVariant::kUncomposed) {
        SolveUncomposed(in, &ws, d);
      } else if (ok) {
        SolveForceLimited(in, &ws, d);
      }
    } else {
      SolveUnlimited(in, ws, d);
    }
  }
  ok = ok && d->f_safe.allFinite();
  // The QP reference checks as the closed form does, so that it reproduces
  // the filter's answer (it stands in for the composed solve only).
  const bool checked_variant =
      variant_ == SafetyVariant::kClosedForm || variant_ == SafetyVariant::kQpReference;
  if (ok && check_each_barrier_ && checked_variant && BreaksABarrierCondition(in, ws, d->f_safe)) {
    // One composed condition bounds only a weighted sum of the barrier
    // derivatives: where the weights of two nearly active barriers trade
    // places from one step to the next, the answer may accelerate freely
    // along another limited axis (docs/safety.md, "Each barrier checked").
    // The replaced answer's report goes with it (a safe stop or an active
    // force limit of the composed solve); SolveUncomposed reports its own.
    d->infeasible = false;
    d->mu_p = d->mu_v = 0.0;
    d->mu_force.setZero();
    d->flags = (d->flags & ~(kFlagFallback | kFlagForceLimited)) | kFlagPerBarrier;
    ok = metric_map_ready || ComputeStepMetricMap(terms, &ws);
    if (ok) SolveUncomposed(in, &ws, d);
    ok = ok && d->f_safe.allFinite();
  }
  if (!ok) {
    // Last resort: nothing trustworthy to filter. Flagged, never F_des.
    d->barriers = BarrierEvaluation{};
    d->mu_p = d->mu_v = 0.0;
    d->mu_position.fill(0.0);
    d->mu_velocity.fill(0.0);
    d->mu_force.setZero();
    // A singular configuration (H) is an implausible pose: invalid input,
    // and no hold brake, which would solve with that H.
    const bool valid = input_valid && !ws.leg_jacobian_degenerate;
    d->filter_case = FilterCase::kFallback;
    d->flags |= kFlagFallback | (valid ? kFlagInfeasible : kFlagInvalidInput);
    d->infeasible = valid;
    d->f_safe = SafeStop(terms, qd, state_valid && !ws.leg_jacobian_degenerate, held_disturbance);
  }
  FinishStep(f_des, d);
  return d->f_safe;
}

void SafetyFilter::FinishStep(const Vector6d& f_des, SafetyDiagnostics* d) {
  if (d->barriers.outside_safe_set) d->flags |= kFlagOutsideSafeSet;
  const Vector6d correction = d->f_safe - f_des;
  d->correction_norm = correction.allFinite() ? correction.norm() : 0.0;
  // A rejected F_des near the double range (1e300 N) overflows the sum of
  // squares; the scaled norm keeps the diagnostics finite (never Inf on a
  // channel), and costs nothing on the steps that do not need it.
  if (std::isinf(d->correction_norm)) d->correction_norm = correction.stableNorm();
  if (!(d->correction_norm == 0.0)) d->flags |= kFlagFilterActive;
  if (d->infeasible) d->flags |= kFlagInfeasible;
}

Vector6d SafetyFilter::SafeStopCommand(const Vector6d& q, const Vector6d& qd,
                                       SafetyDiagnostics* d) {
  return SafeStopCommand(q, qd, GeneralizedDisturbance{}, d);
}

bool SafetyFilter::EvaluateSafeStopTerms(const Vector6d& q, const Vector6d& qd) {
  if (!q.allFinite() || !qd.allFinite()) return false;
  DynamicsTerms& terms = workspace_.terms;
  EvaluateDynamics(platform_, shared_terms_.get(), q, qd, &terms);
  return terms.M.allFinite() && PoseProblems(platform_, q, terms.leg_length_m) == kPosePlausible;
}

Vector6d SafetyFilter::SafeStopCommand(const Vector6d& q, const Vector6d& qd,
                                       const GeneralizedDisturbance& disturbance,
                                       SafetyDiagnostics* d) {
  return SafeStopWithShift(EvaluateSafeStopTerms(q, qd), qd, disturbance, 0.0, d);
}

Vector6d SafetyFilter::SafeStopWithShift(bool terms_valid, const Vector6d& qd,
                                         const GeneralizedDisturbance& disturbance,
                                         double shift_z_n, SafetyDiagnostics* d) const {
  *d = SafetyDiagnostics{};
  d->variant = variant_;
  d->filter_case = FilterCase::kFallback;
  d->flags = kFlagFallback;
  const bool use_d = use_disturbance_ && disturbance.force_n.allFinite();
  Vector6d d_n = use_d ? disturbance.force_n : kNoDisturbance;
  if (use_d) d_n(2) += shift_z_n;
  d->f_safe = SafeStop(workspace_.terms, qd, terms_valid, d_n);
  return d->f_safe;
}

double SafetyFilter::DriveOnShiftN(const Vector6d& q, const Vector6d& qd,
                                   const GeneralizedDisturbance& disturbance) {
  return EvaluateSafeStopTerms(q, qd) ? DriveOnShift(workspace_.terms, qd, disturbance) : 0.0;
}

double SafetyFilter::DriveOnShift(const DynamicsTerms& terms, const Vector6d& qd,
                                  const GeneralizedDisturbance& disturbance) const {
  constexpr int kZ = 2;
  // Answered at once, a lift never builds up: nothing to shift.
  if (!use_disturbance_ || !(drive_on_response_s_ > 0.0) || !disturbance.std_n.allFinite()) {
    return 0.0;
  }
  const VelocityBarrierSpec* limit = nullptr;
  int sides = 0;
  for (int i = 0; i < constraints_.num_velocity; ++i) {
    const VelocityBarrierSpec& s = constraints_.velocity[static_cast<size_t>(i)];
    if (s.source != PositionSource::kAxis || s.index != kZ || s.recovery_of >= 0) continue;
    limit = &s;
    ++sides;
  }
  if (sides != 1) return 0.0;
  Cholesky6 inertia;
  if (!inertia.Compute(terms.M)) return 0.0;
  const double m_inv_zz = inertia.Solve<1>(Vector6d::Unit(kZ))(kZ);
  if (!(m_inv_zz > 0.0)) return 0.0;
  const double worst_n = constraints_.disturbance_sigma * std::max(disturbance.std_n(kZ), 0.0);
  // h_v = sign (zd - limit): the room left to the limit (m/s).
  const double room_mps = std::max(limit->sign * (qd(kZ) - limit->limit), 0.0);
  const double absorbed_n = room_mps / drive_on_response_s_ / m_inv_zz;
  const double shift = std::max(worst_n - absorbed_n, 0.0);
  // More d along +z lifts: the worst case of an upper limit.
  return limit->sign < 0.0 ? shift : -shift;
}

Vector6d SafetyFilter::DriveOnCommand(const Vector6d& q, const Vector6d& qd,
                                      const GeneralizedDisturbance& disturbance,
                                      SafetyDiagnostics* d) {
  const bool valid = EvaluateSafeStopTerms(q, qd);
  const double shift = valid ? DriveOnShift(workspace_.terms, qd, disturbance) : 0.0;
  return SafeStopWithShift(valid, qd, disturbance, shift, d);
}

Vector6d SafetyFilter::SafeStop(const DynamicsTerms& terms, const Vector6d& qd, bool terms_valid,
                                const Vector6d& disturbance_n) const {
  Vector6d f = Vector6d::Zero();
  if (fallback_ == SafetyFallback::kHold && terms_valid) {
    // Gravity-compensating brake: qdd = -qd / stop_time_s, against the
    // estimated model error too (a payload would otherwise sink).
    f = InverseDynamics(terms, -qd / stop_time_s_, disturbance_n);
    // A brake through a (nearly) singular H would be a force without bound.
    if (!f.allFinite() ||
        terms.H.norm() * f.norm() > kMaxLegJacobianCondition * (terms.H * f).norm()) {
      f.setZero();
    }
  }
  if (force_limits_) f = f.cwiseMax(-force_limit_n_).cwiseMin(force_limit_n_);
  return f;
}

void SafetyFilter::ApplySafeStop(const StepInput& in, SafetyDiagnostics* d) const {
  d->filter_case = FilterCase::kFallback;
  d->flags |= kFlagFallback;
  d->f_safe = SafeStop(in.terms, in.qd, true, in.disturbance_n);
}

Matrix6d SafetyFilter::MetricMap(const DynamicsTerms& terms) const {
  BarrierIntermediates x;
  x.inertia_valid = x.inertia.Compute(terms.M);
  LegJacobianFactor factor;  // its own: these terms are not the step's
  Matrix6d l_m, map;
  ComputeMetricMap(terms, x, &factor, &l_m, &map);
  return map;
}

bool SafetyFilter::ComputeStepMetricMap(const DynamicsTerms& terms, FilterWorkspace* ws) const {
  const bool ok =
      ComputeMetricMap(terms, ws->barrier, &ws->leg_jacobian, &ws->metric_factor, &ws->metric_map);
  ws->metric_factor_ready = ok && metric_ != CorrectionMetric::kForce;
  return ok;
}

Matrix6d SafetyFilter::MetricFactor(const DynamicsTerms& terms,
                                    const BarrierIntermediates& x) const {
  // T = H^-1 L: F = T y, cost ||y - y0||^2 = ||L^-1 H dF||^2, which is
  // dqdd^T M dqdd for L = L_M and ||dqdd||^2 for L = M (dqdd = M^-1 H dF).
  return metric_ == CorrectionMetric::kTaskAcceleration ? terms.M : x.inertia.MatrixL();
}

bool SafetyFilter::ComputeMetricMap(const DynamicsTerms& terms, const BarrierIntermediates& x,
                                    LegJacobianFactor* factor, Matrix6d* l, Matrix6d* map) const {
  if (metric_ == CorrectionMetric::kForce) {
    map->setIdentity();
    return true;
  }
  if (!x.inertia_valid) {
    map->setConstant(NAN);
    return false;
  }
  *l = MetricFactor(terms, x);
  if (AccelerationMetricMap(terms.H, *l, factor, map)) return true;
  workspace_.leg_jacobian_degenerate = true;
  return false;
}

bool SafetyFilter::BreaksABarrierCondition(const StepInput& in, const FilterWorkspace& ws,
                                           const Vector6d& f) const {
  const BarrierEvaluation& b = in.barriers;
  const ConstraintSet& c = constraints_;
  if (c.num_velocity > 0 && !ws.barrier.inertia_valid) return false;  // no M^-1: not posable
  // Each condition is affine in F: Psi_i(F) = Psi_i(F_nom) + alpha_i g_i^T dF,
  // as posed by PoseUncomposedQp.
  const Vector6d df = f - in.f_des;
  const Vector6d h_df = in.terms.H * df;  // generalized force of the change
  if (c.num_position > 0 && !b.outside_position_set) {
    const double dpower = -in.qd.dot(h_df);  // g_p^T dF, g_p = -H^T qd (W)
    for (int i = 0; i < c.num_position; ++i) {
      const double at_nominal = OwnPositionCondition(c, b, i);
      const double change = c.position[static_cast<size_t>(i)].alpha * dpower;
      const double tolerance =
          kPerBarrierRelTol * (std::fabs(at_nominal) + std::fabs(change) + c.position_margin);
      if (at_nominal + change < -tolerance) return true;
    }
  }
  if (c.num_velocity > 0) {
    Rhs6<1> dqdd = h_df;  // M^-1 H dF (m/s^2, rad/s^2)
    ws.barrier.inertia.SolveInPlace<1>(&dqdd);
    for (int i = 0; i < c.num_velocity; ++i) {
      const VelocityBarrierSpec& spec = c.velocity[static_cast<size_t>(i)];
      if (!b.velocity_active[static_cast<size_t>(i)]) continue;
      const double at_nominal = OwnVelocityCondition(c, b, i);
      const double change =
          spec.alpha_v * spec.sign *
          (spec.source == PositionSource::kAxis ? dqdd(spec.index)
                                                : in.terms.H.col(spec.index).dot(dqdd));
      const double tolerance =
          kPerBarrierRelTol * (std::fabs(at_nominal) + std::fabs(change) + c.velocity_margin);
      if (at_nominal + change < -tolerance) return true;
    }
  }
  return false;
}

void SafetyFilter::SolveUnlimited(const StepInput& in, const FilterWorkspace& ws,
                                  SafetyDiagnostics* d) const {
  const BarrierEvaluation& b = in.barriers;
  const BarrierIntermediates& x = ws.barrier;
  // The case analysis needs the normals g~ = T^T g only through their dot
  // products. Acceleration metric, T = H^-1 L_M, g_p = -s_p H^T qd,
  // g_v = H^T M^-1 a_c: g~_p = -s_p L_M^T qd and g~_v = L_M^-1 a_c, so
  //   g~_p.g~_p = s_p^2 qd^T M qd,  g~_p.g~_v = -s_p qd^T a_c,
  //   g~_v.g~_v = a_c^T M^-1 a_c,
  // and H cancels: no factor of H unless the correction is non-zero.
  TwoConstraintGram gram;
  gram.psi_p = b.psi_p;
  gram.psi_v = b.psi_v;
  gram.has_p = constraints_.num_position > 0 && !b.outside_position_set;
  gram.has_v = constraints_.num_velocity > 0;
  if (metric_ == CorrectionMetric::kForce) {
    gram.pp = b.g_p.squaredNorm();
    gram.vv = b.g_v.squaredNorm();
    gram.pv = b.g_p.dot(b.g_v);
  } else if (metric_ == CorrectionMetric::kTaskAcceleration) {
    // T = H^-1 M: g~_p = -s_p M qd, g~_v = a_c.
    gram.pp = x.s_p * x.s_p * x.m_qd.squaredNorm();
    gram.vv = x.a_c.squaredNorm();
    gram.pv = -x.s_p * x.m_qd.dot(x.a_c);
  } else {
    gram.pp = x.s_p * x.s_p * x.qd_m_qd;
    gram.vv = x.a_c.dot(x.m_inv_a_c);
    gram.pv = -x.s_p * in.qd.dot(x.a_c);
  }
  TwoConstraintSolution s =
      variant_ == SafetyVariant::kPaperRule ? SolvePaperRule(gram) : SolveExactKkt(gram);
  if (!s.feasible) {
    s = SolveInfeasibleFallback(gram);
    d->infeasible = true;
  }
  d->mu_p = s.mu_p;
  d->mu_v = s.mu_v;
  d->filter_case = s.filter_case;
  if (metric_ == CorrectionMetric::kForce) {
    d->f_safe = in.f_des + s.mu_p * b.g_p + s.mu_v * b.g_v;
  } else if (s.mu_p == 0.0 && s.mu_v == 0.0) {
    d->f_safe = in.f_des;
  } else {
    // F* - F_des = W^-1 (mu_p g_p + mu_v g_v) with W^-1 = H^-1 M H^-T:
    // H (F* - F_des) = mu_v a_c - mu_p s_p M qd, one solve with H.
    Vector6d correction = s.mu_v * x.a_c - (s.mu_p * x.s_p) * x.m_qd;
    // Task accelerations: W^-1 = H^-1 M^2 H^-T, H dF = M (mu_v a_c - mu_p s_p M qd).
    if (metric_ == CorrectionMetric::kTaskAcceleration) correction = in.terms.M * correction;
    if (!SolveWithLegJacobian(in.terms.H, &workspace_.leg_jacobian, &correction)) {
      correction.setConstant(NAN);  // the fallback
      workspace_.leg_jacobian_degenerate = true;
    }
    d->f_safe = in.f_des + correction;
  }
}

bool SafetyFilter::BuildQp(const Matrix6d& map, const BarrierEvaluation& b, const Vector6d& f_des,
                           ProjectionQp* qp, QpRows* rows) const {
  FilterWorkspace ws;  // its own: leaves the data of the filter's step alone
  ws.metric_map = map;
  ComposeProblem(b, &ws);
  // No factor of M here: y0 = T^-1 F_des by a solve with T itself.
  Vector6d y0 = f_des;
  if (metric_ != CorrectionMetric::kForce && !SolvePartialPivot6(map, &y0)) y0.setConstant(NAN);
  const bool posable = PoseQp(y0, ConditionGroups::kAll, &ws);
  *qp = ws.composed.qp;
  if (rows != nullptr) *rows = ws.composed.rows;
  return posable;
}

void SafetyFilter::ComposeProblem(const BarrierEvaluation& b, FilterWorkspace* ws) const {
  ws->problem = MakeProblem(constraints_, b, ws->metric_map, metric_);
}

Vector6d SafetyFilter::MetricCoordinates(const Vector6d& f, const Matrix6d& h,
                                         const BarrierIntermediates& x) const {
  if (metric_ == CorrectionMetric::kForce) return f;
  if (!x.inertia_valid) return Vector6d::Constant(NAN);
  if (metric_ == CorrectionMetric::kTaskAcceleration) return x.inertia.Solve<1>(h * f);
  // T = H^-1 L_M (M = L_M L_M^T): T^-1 f = L_M^-1 H f, a product and a
  // triangular solve instead of a factorisation of T.
  return x.inertia.SolveFactorL(h * f);
}

bool SafetyFilter::PoseQp(const Vector6d& y0, ConditionGroups groups, FilterWorkspace* ws) const {
  const TwoConstraintProblem& problem = ws->problem;
  ProjectionQp& qp = ws->composed.qp;
  QpRows& rows = ws->composed.rows;
  rows = QpRows{};
  qp.m = 0;
  qp.x0 = y0;
  bool posable = true;
  if (problem.has_p) {
    const ConditionRow r = AppendConditionRow(problem.psi_p, problem.g_p, &qp);
    posable = posable && r.posable;
    rows.p = r.row;
    rows.p_norm = r.norm;
  }
  if (problem.has_v && groups != ConditionGroups::kPositionOnly) {
    const ConditionRow r = AppendConditionRow(problem.psi_v, problem.g_v, &qp);
    posable = posable && r.posable;
    rows.v = r.row;
    rows.v_norm = r.norm;
  }
  rows.box = qp.m;
  if (force_limits_) AppendForceLimitRows(ws->metric_map, force_limit_n_, &qp);
  return posable;
}

void SafetyFilter::ReportQpSolution(const double* force_limit_mu, SafetyDiagnostics* d) {
  if (force_limit_mu != nullptr) {
    for (int i = 0; i < kNumLegs; ++i) {
      d->mu_force(i) = force_limit_mu[2 * i + 1] - force_limit_mu[2 * i];
    }
    if ((d->mu_force.array() != 0.0).any()) d->flags |= kFlagForceLimited;
  }
  d->filter_case = d->infeasible ? FilterCase::kInfeasible : CaseFromMultipliers(d->mu_p, d->mu_v);
}

void SafetyFilter::SolveForceLimited(const StepInput& in, FilterWorkspace* ws,
                                     SafetyDiagnostics* d) const {
  ComposeProblem(in.barriers, ws);
  const ProjectionQp& qp = ws->composed.qp;
  const QpRows& rows = ws->composed.rows;
  ProjectionResult& r = ws->composed.result;
  r.status = ProjectionStatus::kInfeasible;
  const Vector6d y0 = MetricCoordinates(in.f_des, in.terms.H, ws->barrier);
  ws->y_des = y0;  // the un-composed QP that may replace this answer poses the same y0
  ws->y_des_of_n = in.f_des;
  ws->y_des_ready = true;
  if (PoseQp(y0, ConditionGroups::kAll, ws)) r = SolveProjectionQp(qp);
  if (r.status != ProjectionStatus::kOptimal) {
    // Keep the position condition and the limits, relax velocity: inside the
    // position set drop it (the position barriers guard the limits), outside
    // it, where the velocity row holds the recovery barriers and nothing else
    // would act, miss it least. Missing it least inside too was measured
    // worse on the P-16P legs (docs/safety.md).
    d->infeasible = true;
    r.status = ProjectionStatus::kInfeasible;
    if (PoseQp(y0, ConditionGroups::kPositionOnly, ws)) r = SolveProjectionQp(qp);
    if (r.status != ProjectionStatus::kOptimal) {
      ApplySafeStop(in, d);
      return;
    }
    if (in.barriers.outside_position_set) RelaxVelocityLeast(y0, ws);
  }
  d->mu_p = ConditionMultiplier(r.mu.data(), rows.p, rows.p_norm);
  d->mu_v = ConditionMultiplier(r.mu.data(), rows.v, rows.v_norm);
  d->f_safe = ForceFromQpSolution(ws->metric_map, r.x, qp.x0, in.f_des);
  ReportQpSolution(force_limits_ ? r.mu.data() + rows.box : nullptr, d);
}

void SafetyFilter::RelaxVelocityLeast(const Vector6d& y0, FilterWorkspace* ws) const {
  const TwoConstraintProblem& problem = ws->problem;
  if (!problem.has_v || !(problem.g_v.norm() > kZeroNormal)) return;
  // How far the answer without the velocity row (position and box) falls
  // short of it: Psi_v + g~_v^T (y - y0) < 0. Relaxing the row by that much
  // keeps this answer feasible; the least relaxation the position row and
  // the box allow lies in [0, shortfall]. Dropping the row instead returns
  // the point of the box nearest F_des: F_des itself when it is inside,
  // which outside the position set (the recovery barriers in the velocity
  // row) is a pass-through of the command the recovery needed changed.
  const double shortfall = -(problem.psi_v + problem.g_v.dot(ws->composed.result.x - y0));
  if (!(shortfall > 0.0)) return;  // that answer meets the velocity row too
  // Posable: the position row was (its answer exists) and the velocity row
  // has a normal. Its unit row a^T y >= b moves by relaxation / |g~_v|.
  PoseQp(y0, ConditionGroups::kAll, ws);
  ProjectionQp& qp = ws->composed.qp;
  const int v = ws->composed.rows.v;
  const double b0 = qp.b(v);
  const double inv_norm = 1.0 / ws->composed.rows.v_norm;
  // Each try is one QP (under 1 us), and only infeasible steps outside the
  // set pay for them (docs/safety.md, "The least relaxation of the velocity
  // row").
  const std::optional<double> least = LeastRelaxation(shortfall, [&](double relaxation) {
    qp.b(v) = b0 - relaxation * inv_norm;
    const ProjectionResult r = SolveProjectionQp(qp);
    if (r.status != ProjectionStatus::kOptimal) return false;
    ws->composed.result = r;
    return true;
  });
  // The QP left in ws is the one its answer solves (a failed try leaves the
  // answer alone).
  if (least) {
    qp.b(v) = b0 - *least * inv_norm;
  } else {
    PoseQp(y0, ConditionGroups::kPositionOnly, ws);
  }
}

void SafetyFilter::SolveReference(const StepInput& in, FilterWorkspace* ws,
                                  SafetyDiagnostics* d) const {
  ComposeProblem(in.barriers, ws);
  const ProjectionQp& qp = ws->composed.qp;
  Vector6d& y = ws->composed.result.x;
  y = in.f_des;
  const bool posable =
      PoseQp(MetricCoordinates(in.f_des, in.terms.H, ws->barrier), ConditionGroups::kAll, ws);
  if (!posable || reference_->Solve(qp, &y) != ProjectionStatus::kOptimal) {
    // The reference has no answer: the closed form's documented fallback.
    SolveUnlimited(in, *ws, d);
    d->infeasible = true;
    d->filter_case = FilterCase::kInfeasible;
    return;
  }
  // Multipliers from stationarity, y - y0 = mu_p g~_p + mu_v g~_v (least squares).
  const TwoConstraintProblem& problem = ws->problem;
  Eigen::Matrix<double, 6, 2> g;
  g << problem.g_p, problem.g_v;
  const Eigen::Vector2d mu = g.colPivHouseholderQr().solve(y - qp.x0);
  d->mu_p = mu.allFinite() ? std::fmax(mu(0), 0.0) : 0.0;
  d->mu_v = mu.allFinite() ? std::fmax(mu(1), 0.0) : 0.0;
  // A condition whose share of the correction is of rounding size (the least
  // squares recovers ~1e-16 for a row the solver left inactive) is not
  // active: the same tolerance as the flag, in the metric's coordinates.
  const double rounding = kReferenceActiveRelTol * std::fmax(qp.x0.norm(), 1.0);
  if (d->mu_p * problem.g_p.norm() <= rounding) d->mu_p = 0.0;
  if (d->mu_v * problem.g_v.norm() <= rounding) d->mu_v = 0.0;
  d->f_safe = ForceFromQpSolution(ws->metric_map, y);
  // The solver's tolerances and the round trip F = T (T^-1 F_nom) leave a
  // correction of rounding size on states no condition cuts: that is F_nom
  // itself, not an intervention (flag "active", docs/safety.md "QP reference").
  const Vector6d correction = d->f_safe - in.f_des;
  if (correction.norm() <= kReferenceActiveRelTol * std::fmax(in.f_des.norm(), 1.0)) {
    d->f_safe = in.f_des;
    d->mu_p = d->mu_v = 0.0;
  }
  ReportQpSolution(nullptr, d);  // the reference solver gives no row multipliers
}

}  // namespace stewart::safety
