#include "stewart/safety/safety_filter.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace stewart::safety {
namespace {

bool TermsFinite(const DynamicsTerms& t) {
  return t.M.allFinite() && t.C_qd.allFinite() && t.G.allFinite() && t.H.allFinite() &&
         t.leg_length_m.allFinite();
}

bool BarriersFinite(const BarrierEvaluation& b) {
  return std::isfinite(b.psi_p) && std::isfinite(b.psi_v) && std::isfinite(b.h_pos) &&
         std::isfinite(b.h_vel) && b.g_p.allFinite() && b.g_v.allFinite();
}

// The two conditions in the metric's coordinates z: g~ = T^T g.
TwoConstraintProblem MakeProblem(const ConstraintSet& c, const BarrierEvaluation& b,
                                 CorrectionMetric metric) {
  TwoConstraintProblem p;
  p.psi_p = b.psi_p;
  p.psi_v = b.psi_v;
  if (metric == CorrectionMetric::kForce) {
    p.g_p = b.g_p;
    p.g_v = b.g_v;
  } else {
    p.g_p.noalias() = b.metric_map.transpose() * b.g_p;
    p.g_v.noalias() = b.metric_map.transpose() * b.g_v;
  }
  p.has_p = c.num_position > 0;
  p.has_v = c.num_velocity > 0;
  return p;
}

// T with T T^T = W^-1 = H^-1 M H^-T for the acceleration metric: T = H^-1 L_M.
// Not finite when H is singular (the caller then falls back).
void ComputeMetricMap(CorrectionMetric metric, const DynamicsTerms& terms, Matrix6d* map) {
  if (metric == CorrectionMetric::kForce) {
    map->setIdentity();
    return;
  }
  const Eigen::LLT<Matrix6d> llt(terms.M);
  const Eigen::PartialPivLU<Matrix6d> lu(terms.H);
  if (llt.info() != Eigen::Success || !(std::fabs(lu.determinant()) > 0.0)) {
    map->setConstant(NAN);
    return;
  }
  *map = lu.solve(Matrix6d(llt.matrixL()));
}

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
      reference_(reference) {
  if (!(force_limit_n_ > 0.0) && force_limits_) {
    throw std::invalid_argument("safety: force limits enabled but actuators.force_limit_n <= 0");
  }
  if (!(stop_time_s_ > 0.0)) throw std::invalid_argument("safety: stop_time_s must be positive");
  if (!(leg_friction_nspm_ >= 0.0)) {
    throw std::invalid_argument("safety: leg_friction_nspm must be >= 0");
  }
  set_variant(variant_);
}

void SafetyFilter::set_variant(SafetyVariant variant) {
  if (variant == SafetyVariant::kQpReference && reference_ == nullptr) {
    throw std::invalid_argument("safety: variant 'qp' needs a reference QP solver");
  }
  variant_ = variant;
}

Vector6d SafetyFilter::Step(const Vector6d& q, const Vector6d& qd, const Vector6d& f_des,
                            SafetyDiagnostics* diagnostics) {
  const auto start = std::chrono::steady_clock::now();
  if (q.allFinite() && qd.allFinite()) {
    EvaluateDynamics(platform_, q, qd, &terms_);
  } else {
    terms_.M.setConstant(NAN);  // marks the terms invalid for StepWithTerms
  }
  const Vector6d f_safe = StepWithTerms(terms_, q, qd, f_des, diagnostics);
  diagnostics->compute_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start)
          .count();
  return f_safe;
}

Vector6d SafetyFilter::StepWithTerms(const DynamicsTerms& terms, const Vector6d& q,
                                     const Vector6d& qd, const Vector6d& f_des,
                                     SafetyDiagnostics* d) const {
  const auto start = std::chrono::steady_clock::now();
  d->variant = variant_;
  d->flags = 0;
  d->infeasible = false;
  d->mu_p = d->mu_v = 0.0;
  d->mu_force.setZero();
  d->f_des = f_des;

  const bool state_valid = q.allFinite() && qd.allFinite() && TermsFinite(terms);
  const bool input_valid =
      state_valid && f_des.allFinite() && f_des.cwiseAbs().maxCoeff() <= kMaxInputForceN;
  bool ok = input_valid;
  if (ok) {
    // The conditions hold for what the legs really push: F + friction.
    const Vector6d f_net_des =
        f_des + LegViscousFriction(leg_friction_nspm_, terms.H.transpose() * qd);
    EvaluateBarriers(constraints_, q, qd, terms, f_net_des, &d->barriers);
    ComputeMetricMap(metric_, terms, &d->barriers.metric_map);
    ok = BarriersFinite(d->barriers) && d->barriers.metric_map.allFinite();
  }
  if (ok) {
    if (variant_ == SafetyVariant::kQpReference) {
      SolveReference(d->barriers, f_des, d);
    } else if (force_limits_) {
      SolveForceLimited(terms, qd, d->barriers, f_des, d);
    } else {
      SolveUnlimited(d->barriers, f_des, d);
    }
    ok = d->f_safe.allFinite();
  }
  if (!ok) {
    // Last resort: nothing trustworthy to filter. Flagged, never F_des.
    d->barriers = BarrierEvaluation{};
    d->mu_p = d->mu_v = 0.0;
    d->mu_force.setZero();
    d->filter_case = FilterCase::kFallback;
    d->flags |= kFlagFallback | (input_valid ? kFlagInfeasible : kFlagInvalidInput);
    d->infeasible = input_valid;
    d->f_safe = SafeStop(terms, qd, state_valid);
  }
  const Vector6d correction = d->f_safe - f_des;
  d->correction_norm = correction.allFinite() ? correction.norm() : 0.0;
  if (!(d->correction_norm == 0.0)) d->flags |= kFlagFilterActive;
  if (d->infeasible) d->flags |= kFlagInfeasible;
  d->compute_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start)
          .count();
  return d->f_safe;
}

Vector6d SafetyFilter::SafeStopCommand(const Vector6d& q, const Vector6d& qd,
                                       SafetyDiagnostics* d) {
  *d = SafetyDiagnostics{};
  d->variant = variant_;
  const bool state_valid = q.allFinite() && qd.allFinite();
  if (state_valid) EvaluateDynamics(platform_, q, qd, &terms_);
  d->filter_case = FilterCase::kFallback;
  d->flags = kFlagFallback;
  d->f_safe = SafeStop(terms_, qd, state_valid && terms_.M.allFinite());
  return d->f_safe;
}

Vector6d SafetyFilter::SafeStop(const DynamicsTerms& terms, const Vector6d& qd,
                                bool terms_valid) const {
  Vector6d f = Vector6d::Zero();
  if (fallback_ == SafetyFallback::kHold && terms_valid) {
    // Gravity-compensating brake: qdd = -qd / stop_time_s.
    f = InverseDynamics(terms, -qd / stop_time_s_);
    if (!f.allFinite()) f.setZero();
  }
  if (force_limits_) f = f.cwiseMax(-force_limit_n_).cwiseMin(force_limit_n_);
  return f;
}

void SafetyFilter::SolveUnlimited(const BarrierEvaluation& b, const Vector6d& f_des,
                                  SafetyDiagnostics* d) const {
  const TwoConstraintProblem problem = MakeProblem(constraints_, b, metric_);
  TwoConstraintSolution s =
      variant_ == SafetyVariant::kPaperRule ? SolvePaperRule(problem) : SolveExactKkt(problem);
  if (!s.feasible) {
    s = SolveInfeasibleFallback(problem);
    d->infeasible = true;
  }
  d->mu_p = s.mu_p;
  d->mu_v = s.mu_v;
  d->filter_case = s.filter_case;
  d->f_safe = f_des + b.metric_map * (s.mu_p * problem.g_p + s.mu_v * problem.g_v);
}

bool SafetyFilter::BuildQp(const BarrierEvaluation& b, const Vector6d& f_des, ProjectionQp* qp,
                           QpRows* rows) const {
  QpRows unused;
  if (rows == nullptr) rows = &unused;
  const bool drop_velocity = rows->drop_velocity;
  *rows = QpRows{};
  rows->drop_velocity = drop_velocity;
  const TwoConstraintProblem problem = MakeProblem(constraints_, b, metric_);
  qp->m = 0;
  // y = T^-1 F; y0 = T^-1 F_des (F_des itself for the force metric).
  if (metric_ == CorrectionMetric::kForce) {
    qp->x0 = f_des;
  } else {
    qp->x0 = b.metric_map.partialPivLu().solve(f_des);
  }
  bool posable = true;
  auto add_cbf = [&](bool present, double psi, const Vector6d& g, int* row) {
    if (!present) return;
    const double norm = g.norm();
    if (!(norm > kZeroNormal)) {
      if (psi < 0.0) posable = false;  // no force can satisfy it
      return;
    }
    // Unit normal: psi + g~^T (y - y0) >= 0  <=>  (g~/|g~|)^T y >= (g~^T y0 - psi)/|g~|.
    qp->a.row(qp->m) = g.transpose() / norm;
    qp->b(qp->m) = (g.dot(qp->x0) - psi) / norm;
    *row = qp->m++;
  };
  add_cbf(constraints_.num_position > 0, problem.psi_p, problem.g_p, &rows->p);
  add_cbf(constraints_.num_velocity > 0 && !rows->drop_velocity, problem.psi_v, problem.g_v,
          &rows->v);
  rows->box = qp->m;
  if (force_limits_) {
    // F_i = T_i y within [-F_max, F_max].
    for (int i = 0; i < kNumLegs; ++i) {
      qp->a.row(qp->m) = b.metric_map.row(i);  // F_i >= -F_max
      qp->b(qp->m++) = -force_limit_n_;
      qp->a.row(qp->m) = -b.metric_map.row(i);  // F_i <= F_max
      qp->b(qp->m++) = -force_limit_n_;
    }
  }
  return posable;
}

void SafetyFilter::SolveForceLimited(const DynamicsTerms& terms, const Vector6d& qd,
                                     const BarrierEvaluation& b, const Vector6d& f_des,
                                     SafetyDiagnostics* d) const {
  ProjectionQp qp;
  ProjectionResult r;
  QpRows rows;
  r.status = ProjectionStatus::kInfeasible;
  if (BuildQp(b, f_des, &qp, &rows)) r = SolveProjectionQp(qp);
  if (r.status != ProjectionStatus::kOptimal) {
    // Keep the position condition and the limits, relax velocity.
    d->infeasible = true;
    rows.drop_velocity = true;
    r.status = ProjectionStatus::kInfeasible;
    if (BuildQp(b, f_des, &qp, &rows)) r = SolveProjectionQp(qp);
    if (r.status != ProjectionStatus::kOptimal) {
      d->filter_case = FilterCase::kFallback;
      d->flags |= kFlagFallback;
      d->f_safe = SafeStop(terms, qd, true);
      return;
    }
  }
  // Map the multipliers of the unit-normal rows back to the conditions' own.
  // The rows hold g~/|g~| (BuildQp), so mu = mu_row / |g~|.
  const TwoConstraintProblem problem = MakeProblem(constraints_, b, metric_);
  if (rows.p >= 0) d->mu_p = r.mu(rows.p) / problem.g_p.norm();
  if (rows.v >= 0) d->mu_v = r.mu(rows.v) / problem.g_v.norm();
  if (force_limits_) {
    for (int i = 0; i < kNumLegs; ++i) {
      d->mu_force(i) = r.mu(rows.box + 2 * i + 1) - r.mu(rows.box + 2 * i);
    }
    if ((d->mu_force.array() != 0.0).any()) d->flags |= kFlagForceLimited;
  }
  d->f_safe = ForceFromQpSolution(b, r.x);
  d->filter_case = d->infeasible ? FilterCase::kInfeasible : CaseFromMultipliers(d->mu_p, d->mu_v);
}

void SafetyFilter::SolveReference(const BarrierEvaluation& b, const Vector6d& f_des,
                                  SafetyDiagnostics* d) const {
  ProjectionQp qp;
  Vector6d y = f_des;
  const bool posable = BuildQp(b, f_des, &qp);
  if (!posable || reference_->Solve(qp, &y) != ProjectionStatus::kOptimal) {
    // The reference has no answer: the closed form's documented fallback.
    SolveUnlimited(b, f_des, d);
    d->infeasible = true;
    d->filter_case = FilterCase::kInfeasible;
    return;
  }
  // Multipliers from stationarity, y - y0 = mu_p g~_p + mu_v g~_v (least squares).
  const TwoConstraintProblem problem = MakeProblem(constraints_, b, metric_);
  Eigen::Matrix<double, 6, 2> g;
  g << problem.g_p, problem.g_v;
  const Eigen::Vector2d mu = g.colPivHouseholderQr().solve(y - qp.x0);
  d->mu_p = mu.allFinite() ? std::fmax(mu(0), 0.0) : 0.0;
  d->mu_v = mu.allFinite() ? std::fmax(mu(1), 0.0) : 0.0;
  d->filter_case = CaseFromMultipliers(d->mu_p, d->mu_v);
  d->f_safe = ForceFromQpSolution(b, y);
}

}  // namespace stewart::safety
