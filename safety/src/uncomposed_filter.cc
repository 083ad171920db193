// Variant `uncomposed` of SafetyFilter (uncomposed_qp.h, docs/safety.md "The
// un-composed QP"): every barrier its own row, solved exactly by the dual
// active-set method. Kept in its own file: nothing here runs for the other
// variants.
#include <cmath>

#include "stewart/model/linear_algebra6.h"
#include "stewart/safety/safety_filter.h"

namespace stewart::safety {
namespace {

// The case the diagnostics report: which groups have a positive multiplier.
FilterCase CaseFromGroups(double mu_p, double mu_v) {
  if (mu_p > 0.0 && mu_v > 0.0) return FilterCase::kBoth;
  if (mu_p > 0.0) return FilterCase::kPosition;
  if (mu_v > 0.0) return FilterCase::kVelocity;
  return FilterCase::kNone;
}

// Largest t in [0, 1] such that y + t dy keeps every row of `qp` (which y
// satisfies, up to rounding).
double StepKeepingRows(const UncomposedQp& qp, const Vector6d& y, const Vector6d& dy) {
  double t = 1.0;
  for (int r = 0; r < qp.m; ++r) {
    const double rate = qp.a.row(r).dot(dy);
    if (!(rate < 0.0)) continue;
    const double slack = std::fmax(qp.a.row(r).dot(y) - qp.b(r), 0.0);
    t = std::fmin(t, slack / -rate);
  }
  return t;
}

}  // namespace

bool SafetyFilter::BuildUncomposedQp(const DynamicsTerms& terms, const Vector6d& qd,
                                     const Matrix6d& map, const BarrierEvaluation& b,
                                     const Vector6d& f_des, UncomposedQp* qp,
                                     UncomposedQpRows* rows) const {
  UncomposedQpRows unused;
  if (rows == nullptr) rows = &unused;
  Cholesky6 inertia;
  if (!inertia.Compute(terms.M) && constraints_.num_velocity > 0) {
    qp->m = 0;
    return false;  // the velocity rows need M^-1
  }
  return BuildUncomposedQp(terms, qd, inertia, map, b, f_des, qp, rows);
}

bool SafetyFilter::BuildUncomposedQp(const DynamicsTerms& terms, const Vector6d& qd,
                                     const Cholesky6& inertia, const Matrix6d& map,
                                     const BarrierEvaluation& b, const Vector6d& f_des,
                                     UncomposedQp* qp, UncomposedQpRows* rows) const {
  const bool drop_position = rows->drop_position, drop_velocity = rows->drop_velocity;
  *rows = UncomposedQpRows{};
  rows->drop_position = drop_position;
  rows->drop_velocity = drop_velocity;
  rows->position_row.fill(-1);
  rows->velocity_row.fill(-1);
  const ConstraintSet& c = constraints_;
  const bool force_metric = metric_ == CorrectionMetric::kForce;
  qp->m = 0;
  // y = T^-1 F; y0 = T^-1 F_des (F_des itself for the force metric), as BuildQp.
  qp->x0 = f_des;
  if (!force_metric && !SolvePartialPivot6(map, &qp->x0)) qp->x0.setConstant(NAN);
  bool posable = true;
  // Condition psi + n~^T (y - y0) >= 0 with n~ = T^T n, as a unit-normal row.
  auto add_row = [&](double psi, const Vector6d& normal, int* row, double* norm) {
    const double length = normal.norm();
    if (!(length > kZeroNormal)) {
      if (psi < 0.0) posable = false;  // no force can satisfy it
      return;
    }
    qp->a.row(qp->m) = normal.transpose() / length;
    qp->b(qp->m) = (normal.dot(qp->x0) - psi) / length;
    *norm = length;
    *row = qp->m++;
  };

  if (c.num_position > 0 && !drop_position) {
    // dh_D,i/dF = -H^T qd for every position barrier (the power term): the
    // rows differ only by alpha_i and their offsets.
    Vector6d g = -(terms.H.transpose() * qd);
    if (!force_metric) g = map.transpose() * g;
    for (int i = 0; i < c.num_position; ++i) {
      const size_t k = static_cast<size_t>(i);
      const double alpha = c.position[k].alpha;
      // alpha_i (dh_i + h_i) - delta_p at F_des (+ friction: barriers.h).
      const double psi = b.alpha_h_position[k] + alpha * b.dh_position[k] - c.position_margin;
      add_row(psi, alpha * g, &rows->position_row[k], &rows->position_norm[k]);
    }
  }
  if (c.num_velocity > 0 && !drop_velocity) {
    // dh_v,i/dF = H^T M^-1 a_i with a_i = sign_i e_axis: column `axis` of
    // H^T M^-1 (M^-1 is symmetric), mapped to y by T^T.
    Rhs6<6> m_inv = Rhs6<6>::Identity();
    inertia.SolveInPlace<6>(&m_inv);
    Matrix6d g = terms.H.transpose() * m_inv;
    if (!force_metric) g = map.transpose() * g;
    for (int i = 0; i < c.num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      const VelocityBarrierSpec& s = c.velocity[k];
      const double psi = b.alpha_h_velocity[k] + s.alpha_v * b.dh_velocity[k] - c.velocity_margin;
      add_row(psi, (s.alpha_v * s.sign) * g.col(s.axis), &rows->velocity_row[k],
              &rows->velocity_norm[k]);
    }
  }
  rows->box = qp->m;
  if (force_limits_) AppendForceLimitRows(map, force_limit_n_, qp);
  return posable;
}

void SafetyFilter::SolveUncomposed(const DynamicsTerms& terms, const Vector6d& qd,
                                   const BarrierIntermediates& x, const Matrix6d& map,
                                   const BarrierEvaluation& b, const Vector6d& f_des,
                                   SafetyDiagnostics* d) const {
  UncomposedQp qp;
  UncomposedQpRows rows;
  UncomposedQpResult r;
  r.status = ProjectionStatus::kInfeasible;
  if (BuildUncomposedQp(terms, qd, x.inertia, map, b, f_des, &qp, &rows)) {
    r = SolveProjectionQp(qp);
  }
  // Multiplier of each posed row, and the velocity rows' share of the step
  // (below 1 only in the unlimited fallback).
  UncomposedQpRows velocity_rows = rows;
  UncomposedQpResult velocity_result;
  velocity_result.mu.setZero();
  double velocity_share = 1.0;
  bool split = false;
  Vector6d y = r.x;
  if (r.status != ProjectionStatus::kOptimal) {
    d->infeasible = true;
    if (force_limits_) {
      // As the force-limited composed filter: keep the position rows and the
      // limits, relax velocity; if that fails too, the safe stop.
      rows = UncomposedQpRows{};
      rows.drop_velocity = true;
      r.status = ProjectionStatus::kInfeasible;
      if (BuildUncomposedQp(terms, qd, x.inertia, map, b, f_des, &qp, &rows)) {
        r = SolveProjectionQp(qp);
      }
      if (r.status != ProjectionStatus::kOptimal) {
        d->filter_case = FilterCase::kFallback;
        d->flags |= kFlagFallback;
        d->f_safe = SafeStop(terms, qd, true);
        return;
      }
      y = r.x;
    } else {
      // As the closed form's fallback (SolveInfeasibleFallback), per row:
      // meet the position rows with the least correction, then move toward
      // the velocity rows' projection only as far as the position rows
      // allow; when no force can meet the position rows (at rest outside the
      // set), the velocity rows alone.
      rows = UncomposedQpRows{};
      rows.drop_velocity = true;
      const bool position_posable =
          BuildUncomposedQp(terms, qd, x.inertia, map, b, f_des, &qp, &rows);
      r.status = ProjectionStatus::kInfeasible;
      if (position_posable) r = SolveProjectionQp(qp);
      const bool keep_position = r.status == ProjectionStatus::kOptimal;
      if (!keep_position) {
        r = UncomposedQpResult{};
        r.mu.setZero();
        r.x = qp.x0;
        rows.position_row.fill(-1);
      }
      UncomposedQp velocity_qp;
      velocity_rows = UncomposedQpRows{};
      velocity_rows.drop_position = true;
      velocity_result.status = ProjectionStatus::kInfeasible;
      if (BuildUncomposedQp(terms, qd, x.inertia, map, b, f_des, &velocity_qp, &velocity_rows)) {
        velocity_qp.x0 = r.x;  // the rows' offsets stay those of y0 = T^-1 F_des
        velocity_result = SolveProjectionQp(velocity_qp);
      }
      const bool velocity_ok = velocity_result.status == ProjectionStatus::kOptimal;
      if (!velocity_ok) velocity_result.mu.setZero();
      if (!keep_position && !velocity_ok) {
        d->filter_case = FilterCase::kFallback;
        d->flags |= kFlagFallback;
        d->f_safe = SafeStop(terms, qd, true);
        return;
      }
      split = true;
      y = r.x;
      velocity_share = 0.0;
      if (velocity_ok) {
        const Vector6d dy = velocity_result.x - r.x;
        velocity_share = keep_position ? StepKeepingRows(qp, r.x, dy) : 1.0;
        y += velocity_share * dy;
      }
    }
  }

  // Back to each condition's own multiplier: the rows hold n~/|n~|.
  const ConstraintSet& c = constraints_;
  double mu_p = 0.0, mu_v = 0.0;
  for (int i = 0; i < c.num_position; ++i) {
    const size_t k = static_cast<size_t>(i);
    const int row = rows.position_row[k];
    if (row >= 0) d->mu_position[k] = r.mu(row) / rows.position_norm[k];
    mu_p += d->mu_position[k];
  }
  const UncomposedQpRows& v_rows = split ? velocity_rows : rows;
  for (int i = 0; i < c.num_velocity; ++i) {
    const size_t k = static_cast<size_t>(i);
    const int row = v_rows.velocity_row[k];
    if (row >= 0) {
      const double mu_row = split ? velocity_share * velocity_result.mu(row) : r.mu(row);
      d->mu_velocity[k] = mu_row / v_rows.velocity_norm[k];
    }
    mu_v += d->mu_velocity[k];
  }
  d->mu_p = mu_p;
  d->mu_v = mu_v;
  if (force_limits_) {
    for (int i = 0; i < kNumLegs; ++i) {
      d->mu_force(i) = r.mu(rows.box + 2 * i + 1) - r.mu(rows.box + 2 * i);
    }
    if ((d->mu_force.array() != 0.0).any()) d->flags |= kFlagForceLimited;
  }
  d->f_safe = ForceFromQpSolution(map, y, qp.x0, f_des);
  d->filter_case = d->infeasible ? FilterCase::kInfeasible : CaseFromGroups(mu_p, mu_v);
}

}  // namespace stewart::safety
