// Variant `uncomposed` of SafetyFilter (uncomposed_qp.h, docs/safety.md "The
// un-composed QP"): every barrier its own row, solved exactly by the dual
// active-set method. Kept in its own file: nothing here runs for the other
// variants.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <optional>

#include "stewart/model/linear_algebra6.h"
#include "stewart/safety/least_relaxation.h"
#include "stewart/safety/safety_filter.h"

namespace stewart::safety {
namespace {

const Vector6d kZero6 = Vector6d::Zero();

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

// Solves `data` as posed; false (and status kInfeasible) when it was not posable.
bool SolvePosed(bool posable, UncomposedQpData* data) {
  data->result.status = ProjectionStatus::kInfeasible;
  if (posable) data->result = SolveProjectionQp(data->qp);
  return data->result.status == ProjectionStatus::kOptimal;
}

}  // namespace

bool SafetyFilter::BuildUncomposedQp(const DynamicsTerms& terms, const Vector6d& qd,
                                     const Matrix6d& map, const BarrierEvaluation& b,
                                     const Vector6d& f_des, UncomposedQp* qp,
                                     UncomposedQpRows* rows) const {
  FilterWorkspace ws;  // its own: leaves the data of the filter's step alone
  ws.barrier.inertia_valid = ws.barrier.inertia.Compute(terms.M);
  if (!ws.barrier.inertia_valid &&
      (constraints_.num_velocity > 0 || metric_ != CorrectionMetric::kForce)) {
    qp->m = 0;
    return false;  // the velocity rows need M^-1, the acceleration metric L_M
  }
  ws.metric_map = map;
  const bool posable = PoseUncomposedQp(StepInput{terms, qd, f_des, b, kZero6},
                                        ConditionGroups::kAll, ws, &ws.uncomposed);
  *qp = ws.uncomposed.qp;
  if (rows != nullptr) *rows = ws.uncomposed.rows;
  return posable;
}

bool SafetyFilter::PoseUncomposedQp(const StepInput& in, ConditionGroups groups,
                                    const FilterWorkspace& ws, UncomposedQpData* out) const {
  const DynamicsTerms& terms = in.terms;
  const BarrierEvaluation& b = in.barriers;
  const Matrix6d& map = ws.metric_map;  // the force-limit rows' T
  UncomposedQp& qp = out->qp;
  UncomposedQpRows& rows = out->rows;
  rows = UncomposedQpRows{};
  rows.position_row.fill(-1);
  rows.velocity_row.fill(-1);
  const ConstraintSet& c = constraints_;
  const bool force_metric = metric_ == CorrectionMetric::kForce;
  qp.m = 0;
  // The map is T = H^-1 L (MetricFactor: L_M with M = L_M L_M^T for the
  // kinetic metric, M for task accelerations), so in y = T^-1 F every normal
  // and y0 need L alone, not T:
  //   y0 = T^-1 F_des = L^-1 H F_des,
  //   T^T (-H^T qd) = -L^T qd                          (position rows),
  //   T^T H^T M^-1 e_j = L^T M^-1 e_j                  (velocity rows:
  //     L_M^-1 e_j, a triangular solve; e_j itself for L = M),
  // instead of solves with T and 6x6 products.
  Matrix6d metric_l;
  if (!force_metric) {
    metric_l = ws.metric_factor_ready ? ws.metric_factor : MetricFactor(terms, ws.barrier);
  }
  qp.x0 = ws.y_des_ready && ws.y_des_of_n == in.f_des
              ? ws.y_des
              : MetricCoordinates(in.f_des, terms.H, ws.barrier);
  bool posable = true;

  if (c.num_position > 0 && groups != ConditionGroups::kVelocityOnly && !b.outside_position_set) {
    // dh_D,i/dF = -H^T qd for every position barrier (the power term): the
    // rows share one direction and differ only by alpha_i and their offsets.
    // Of rows with one normal only the one with the largest offset can bind
    // (it implies the others), so that one alone is posed: the feasible set,
    // hence the optimum, is the same, and the others' multipliers are 0.
    const Vector6d g = force_metric ? Vector6d(-(terms.H.transpose() * in.qd))
                                    : Vector6d(-(metric_l.transpose() * in.qd));
    const double g_norm = g.norm();
    const double g_dot_x0 = g.dot(qp.x0);
    int best = -1;
    double best_b = 0.0, best_norm = 0.0;
    for (int i = 0; i < c.num_position; ++i) {
      const double alpha = c.position[static_cast<size_t>(i)].alpha;
      // alpha_i (dh_i + h_i) - delta_p at F_des (+ friction: barriers.h).
      const double psi = OwnPositionCondition(c, b, i);
      const double norm = alpha * g_norm;
      if (!(norm > kZeroNormal)) {
        posable = posable && !(psi < 0.0);  // the force cannot change it
        continue;
      }
      const double offset = (alpha * g_dot_x0 - psi) / norm;
      if (best < 0 || offset > best_b) {
        best = i;
        best_b = offset;
        best_norm = norm;
      }
    }
    if (best >= 0) {
      STEWART_CHECK(qp.m < UncomposedQp::kMaxRows, "PoseUncomposedQp: no row left");
      const size_t k = static_cast<size_t>(best);
      qp.a.row(qp.m) = g.transpose() / g_norm;
      qp.b(qp.m) = best_b;
      rows.position_row[k] = qp.m++;
      rows.position_norm[k] = best_norm;
    }
  }
  if (c.num_velocity > 0 && groups != ConditionGroups::kPositionOnly) {
    // dh_v,i/dF = H^T M^-1 a_i with a_i = sign_i e_axis (or sign_i H(:, leg)),
    // mapped to y by T^T: (H^T M^-1) a_i for the force metric, L_M^-1 a_i for
    // the acceleration metric.
    Matrix6d g;
    if (force_metric) {
      Rhs6<6> m_inv = Rhs6<6>::Identity();
      ws.barrier.inertia.SolveInPlace<6>(&m_inv);
      g = terms.H.transpose() * m_inv;
    } else if (metric_ == CorrectionMetric::kTaskAcceleration) {
      g.setIdentity();  // T^T H^T M^-1 = M M^-1
    } else {
      // L_M^-1, lower triangular, column by column (forward substitution).
      const Vector6d inv_diag = metric_l.diagonal().cwiseInverse();
      g.setZero();
      for (int j = 0; j < 6; ++j) {
        g(j, j) = inv_diag(j);
        for (int i = j + 1; i < 6; ++i) {
          double sum = 0.0;
          for (int k = j; k < i; ++k) sum += metric_l(i, k) * g(k, j);
          g(i, j) = -sum * inv_diag(i);
        }
      }
    }
    for (int i = 0; i < c.num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      const VelocityBarrierSpec& s = c.velocity[k];
      if (!b.velocity_active[k]) {
        rows.velocity_row[k] = -1;
        continue;
      }
      const double psi = OwnVelocityCondition(c, b, i);
      const Vector6d normal = s.source == PositionSource::kAxis
                                  ? Vector6d((s.alpha_v * s.sign) * g.col(s.index))
                                  : Vector6d((s.alpha_v * s.sign) * (g * terms.H.col(s.index)));
      const ConditionRow r = AppendConditionRow(psi, normal, &qp);
      posable = posable && r.posable;
      rows.velocity_row[k] = r.row;
      rows.velocity_norm[k] = r.norm;
    }
  }
  rows.box = qp.m;
  if (force_limits_) AppendForceLimitRows(map, force_limit_n_, &qp);
  return posable;
}

void SafetyFilter::RelaxUncomposedVelocityLeast(const StepInput& in, FilterWorkspace* ws) const {
  UncomposedQpData& main = ws->uncomposed;  // the position rows' and the box's answer
  UncomposedQpData& all = ws->velocity_alone;
  // Every row; a velocity row whose normal is zero is left out (no force
  // changes it), so this posing is used whether or not it is posable.
  PoseUncomposedQp(in, ConditionGroups::kAll, *ws, &all);
  // The rows hold unit normals: b_i - a_i^T y is the distance, in the
  // metric, by which y misses row i. The largest over the velocity rows at
  // the answer without them bounds the least common relaxation.
  const ConstraintSet& c = constraints_;
  std::array<double, kMaxVelocityBarriers> b0{};
  double shortfall = 0.0;
  for (int i = 0; i < c.num_velocity; ++i) {
    const int row = all.rows.velocity_row[static_cast<size_t>(i)];
    if (row < 0) continue;
    b0[static_cast<size_t>(i)] = all.qp.b(row);
    shortfall = std::fmax(shortfall, all.qp.b(row) - all.qp.a.row(row).dot(main.result.x));
  }
  if (!(shortfall > 0.0)) return;
  const auto relax = [&](double relaxation) {
    for (int i = 0; i < c.num_velocity; ++i) {
      const int row = all.rows.velocity_row[static_cast<size_t>(i)];
      if (row >= 0) all.qp.b(row) = b0[static_cast<size_t>(i)] - relaxation;
    }
  };
  // One relaxation shared by every velocity row (the least worst miss), as
  // the composed filter's RelaxVelocityLeast.
  const std::optional<double> least = LeastRelaxation(shortfall, [&](double relaxation) {
    relax(relaxation);
    all.result = SolveProjectionQp(all.qp);
    if (all.result.status != ProjectionStatus::kOptimal) return false;
    main.result = all.result;
    return true;
  });
  if (!least) return;
  // The QP and rows left in `main` are the ones its answer solves.
  relax(*least);
  main.qp = all.qp;
  main.rows = all.rows;
}

void SafetyFilter::SolveUncomposed(const StepInput& in, FilterWorkspace* ws,
                                   SafetyDiagnostics* d) const {
  UncomposedQpData& main = ws->uncomposed;
  UncomposedQpData& velocity = ws->velocity_alone;
  const UncomposedQp& qp = main.qp;
  const UncomposedQpRows& rows = main.rows;
  UncomposedQpResult& r = main.result;
  // The velocity rows' share of the step: below 1 only in the unlimited
  // fallback, which solves them apart (split).
  double velocity_share = 1.0;
  bool split = false;
  bool ok = SolvePosed(PoseUncomposedQp(in, ConditionGroups::kAll, *ws, &main), &main);
  Vector6d y = r.x;
  if (!ok) {
    d->infeasible = true;
    if (force_limits_) {
      // As the force-limited composed filter: keep the position rows and the
      // limits, drop the velocity rows inside the position set and miss them
      // least outside it; if the position rows and the limits fail too, the
      // safe stop.
      ok = SolvePosed(PoseUncomposedQp(in, ConditionGroups::kPositionOnly, *ws, &main), &main);
      if (!ok) {
        ApplySafeStop(in, d);
        return;
      }
      if (in.barriers.outside_position_set) RelaxUncomposedVelocityLeast(in, ws);
      y = r.x;
    } else {
      // As the closed form's fallback (SolveInfeasibleFallback), per row:
      // meet the position rows with the least correction, then move toward
      // the velocity rows' projection only as far as the position rows
      // allow. When no force can meet the position rows (a violated row
      // with a zero normal: at rest within a position margin), the
      // documented safe stop, flagged as the force-limited case above
      // (docs/safety.md, "Infeasibility fallback").
      if (!SolvePosed(PoseUncomposedQp(in, ConditionGroups::kPositionOnly, *ws, &main), &main)) {
        ApplySafeStop(in, d);
        return;
      }
      velocity.result.status = ProjectionStatus::kInfeasible;
      if (PoseUncomposedQp(in, ConditionGroups::kVelocityOnly, *ws, &velocity)) {
        velocity.qp.x0 = r.x;  // the rows' offsets stay those of y0 = T^-1 F_des
        velocity.result = SolveProjectionQp(velocity.qp);
      }
      const bool velocity_ok = velocity.result.status == ProjectionStatus::kOptimal;
      if (!velocity_ok) velocity.result.mu.setZero();
      split = true;
      y = r.x;
      velocity_share = 0.0;
      if (velocity_ok) {
        const Vector6d dy = velocity.result.x - r.x;
        velocity_share = StepKeepingRows(qp, r.x, dy);
        y += velocity_share * dy;
      }
    }
  }

  // Back to each condition's own multiplier: the rows hold n~/|n~|.
  const ConstraintSet& c = constraints_;
  double mu_p = 0.0, mu_v = 0.0;
  for (int i = 0; i < c.num_position; ++i) {
    const size_t k = static_cast<size_t>(i);
    d->mu_position[k] =
        ConditionMultiplier(r.mu.data(), rows.position_row[k], rows.position_norm[k]);
    mu_p += d->mu_position[k];
  }
  const UncomposedQpRows& v_rows = split ? velocity.rows : rows;
  for (int i = 0; i < c.num_velocity; ++i) {
    const size_t k = static_cast<size_t>(i);
    const int row = v_rows.velocity_row[k];
    if (row >= 0) {
      const double mu_row = split ? velocity_share * velocity.result.mu(row) : r.mu(row);
      d->mu_velocity[k] = mu_row / v_rows.velocity_norm[k];
    }
    mu_v += d->mu_velocity[k];
  }
  d->mu_p = mu_p;
  d->mu_v = mu_v;
  d->f_safe = ForceFromQpSolution(ws->metric_map, y, qp.x0, in.f_des);
  ReportQpSolution(force_limits_ ? r.mu.data() + rows.box : nullptr, d);
}

}  // namespace stewart::safety
