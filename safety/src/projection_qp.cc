#include "stewart/safety/projection_qp.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "stewart/safety/uncomposed_qp.h"

namespace stewart::safety {
namespace {

constexpr double kFeasTol = 1e-12;  // relative to |b| + |a| |x|
// An active row whose residual is below this (relative to |b| + |a| |x|, as
// kFeasTol: 100x tighter) needs no re-solve: a few roundings of a 6-term dot.
constexpr double kPolishTol = 1e-14;
constexpr double kDependentTol = 1e-20;  // ||z||^2 vs ||a_p||^2: a_p in span
// Each iteration adds one constraint, and a constraint may leave and come
// back: 4 iterations per row, and never fewer than 60, the bound the composed
// filter's 14-row QP is verified with (4 per row would give it 56).
template <int MaxRows>
constexpr int kMaxIterations = std::max(60, 4 * MaxRows);

// std::fmax / std::fmin are calls into libm here (their NaN rules): these
// are inline, with the same answer where b is never NaN.
inline double MaxOf(double a, double b) { return a > b ? a : b; }  // b if a is NaN
inline double MinOf(double a, double b) { return a < b ? a : b; }  // b if a is NaN

using ActiveMatrix = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6>;
using ActiveVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using ActiveGram = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

// Householder QR of the 6 x k matrix whose columns are k <= 6 normals, in
// fixed storage (LAPACK's convention: H_j = I - tau_j v_j v_j^T with
// v_j(j) = 1, Q = H_0 ... H_{k-1}); the same factors as Eigen's
// HouseholderQR, without its dynamic-size machinery.
class NormalsQr {
 public:
  explicit NormalsQr(int k) : k_(k) {}
  double* column(int j) { return a_[j]; }

  void Factor() {
    for (int j = 0; j < k_; ++j) {
      double* c = a_[j];
      double tail = 0.0;
      for (int i = j + 1; i < 6; ++i) tail += c[i] * c[i];
      const double head = c[j];
      if (tail == 0.0) {  // already upper triangular in this column
        tau_[j] = 0.0;
        continue;
      }
      const double norm = std::sqrt(head * head + tail);
      const double beta = head >= 0.0 ? -norm : norm;
      tau_[j] = (beta - head) / beta;
      const double scale = 1.0 / (head - beta);
      for (int i = j + 1; i < 6; ++i) c[i] *= scale;
      c[j] = beta;
      for (int col = j + 1; col < k_; ++col) {
        double* d = a_[col];
        double w = d[j];
        for (int i = j + 1; i < 6; ++i) w += c[i] * d[i];
        w *= tau_[j];
        d[j] -= w;
        for (int i = j + 1; i < 6; ++i) d[i] -= w * c[i];
      }
    }
  }
  double r(int i, int j) const { return a_[j][i]; }  // i <= j
  /// Q [z; 0] for z of length k.
  Vector6d ApplyQ(const double* z) const {
    Vector6d y = Vector6d::Zero();
    for (int j = 0; j < k_; ++j) y(j) = z[j];
    for (int j = k_ - 1; j >= 0; --j) {
      const double* c = a_[j];
      double w = y(j);
      for (int i = j + 1; i < 6; ++i) w += c[i] * y(i);
      w *= tau_[j];
      y(j) -= w;
      for (int i = j + 1; i < 6; ++i) y(i) -= w * c[i];
    }
    return y;
  }

 private:
  int k_;
  double a_[6][6]{};  // a_[j]: column j (the normal, then R above and v below the diagonal)
  double tau_[6]{};
};

// Re-solves the final active set directly so the active constraints hold to
// rounding, whatever the path the iteration took: x = x0 + N^T mu with
// N N^T mu = b_N - N x0, through the QR factors of N^T = Q R (so that
// x - x0 = Q R^-T r and mu = R^-1 R^-T r). Not through the Gram N N^T: two
// nearly parallel active normals (a position row and a velocity row near a
// limit, multipliers ~1e7) would square its condition number and leave the
// constraints violated by ~1e-10 relative. One step of refinement on the
// residual takes the rest.
//
// Where the iterations already left every active row holding to within
// kPolishTol (well-conditioned normals: almost always), the re-solve would
// move x by rounding only and is skipped: it was 15 % of a step whose force
// box binds, and the re-solve's accuracy is what the check below measures.
template <int MaxRows>
void Polish(const ProjectionQpN<MaxRows>& qp, const std::array<int, 6>& active, int num_active,
            const Eigen::Matrix<double, MaxRows, 1>& row_norm, ProjectionResultN<MaxRows>* res) {
  if (num_active == 0) return;
  const double x_norm = res->x.norm();
  bool rows_hold = true;
  for (int j = 0; j < num_active; ++j) {
    const int i = active[static_cast<size_t>(j)];
    const double residual = qp.b(i) - qp.a.row(i).dot(res->x);
    rows_hold = rows_hold &&
                std::fabs(residual) <= kPolishTol * (std::fabs(qp.b(i)) + row_norm(i) * x_norm);
  }
  if (rows_hold) return;
  if (num_active == 1) {
    // One active row a: x = x0 + mu a with a^T x = b, mu = (b - a^T x0) / |a|^2,
    // and one step of refinement on the residual, as below.
    const int i = active[0];
    const Vector6d a = qp.a.row(i).transpose();
    const double aa = a.squaredNorm();
    const double rhs = qp.b(i) - a.dot(qp.x0);
    double mu = rhs / aa;
    Vector6d dx = mu * a;
    const double correction = (rhs - a.dot(dx)) / aa;
    mu += correction;
    dx += correction * a;
    if (!dx.allFinite() || !std::isfinite(mu) || mu < 0.0) return;
    res->x = qp.x0 + dx;
    res->mu(i) = mu;
    return;
  }
  const int k = num_active;
  NormalsQr qr(k);
  double rhs[6];
  for (int j = 0; j < k; ++j) {
    const int i = active[static_cast<size_t>(j)];
    double* c = qr.column(j);
    for (int e = 0; e < 6; ++e) c[e] = qp.a(i, e);
    rhs[j] = qp.b(i) - qp.a.row(i).dot(qp.x0);
  }
  qr.Factor();
  double r_max = 0.0, r_min = HUGE_VAL;
  for (int j = 0; j < k; ++j) {
    r_max = std::fmax(r_max, std::fabs(qr.r(j, j)));
    r_min = std::fmin(r_min, std::fabs(qr.r(j, j)));
  }
  if (!(r_min > 1e-14 * r_max)) return;
  Vector6d dx = Vector6d::Zero();
  double mu[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  double residual[6];
  for (int j = 0; j < k; ++j) residual[j] = rhs[j];
  for (int pass = 0; pass < 2; ++pass) {
    double z[6];
    for (int j = 0; j < k; ++j) {  // R^T z = residual
      double sum = residual[j];
      for (int i = 0; i < j; ++i) sum -= qr.r(i, j) * z[i];
      z[j] = sum / qr.r(j, j);
    }
    dx += qr.ApplyQ(z);
    for (int j = k - 1; j >= 0; --j) {  // R dmu = z
      double sum = z[j];
      for (int i = j + 1; i < k; ++i) sum -= qr.r(j, i) * z[i];
      z[j] = sum / qr.r(j, j);
      mu[j] += z[j];
    }
    for (int j = 0; j < k; ++j) {
      residual[j] = rhs[j] - qp.a.row(active[static_cast<size_t>(j)]).dot(dx);
    }
  }
  bool ok = dx.allFinite();
  for (int j = 0; j < k; ++j) ok = ok && std::isfinite(mu[j]) && !(mu[j] < 0.0);
  if (!ok) return;
  res->x = qp.x0 + dx;
  for (int j = 0; j < k; ++j) res->mu(active[static_cast<size_t>(j)]) = mu[j];
}

// The active normals (rows[0..k)) and a Cholesky factor L of their Gram
// N N^T in fixed storage, kept across the iterations: a normal added at the
// end extends L by one row from the forward substitution its step direction
// already did; a dropped one re-orders the rows, and L is factored afresh at
// the next solve. (Eigen's dynamic-size LDLT, once used for every solve, was
// 14 % of the worst step's profile.)
class ActiveNormals {
 public:
  int size() const { return k_; }
  const Vector6d& row(int j) const { return rows_[static_cast<size_t>(j)]; }

  /// r solving (N N^T) r = N a_p; false when a pivot is not positive and
  /// finite or r is not finite (normals dependent to rounding): r is then
  /// meaningless and the caller takes the pivoted LDLT.
  bool Solve(const Vector6d& a_p, double r[6]) {
    last_solve_valid_ = false;
    if (!factor_valid_ && !Factor()) return false;
    for (int i = 0; i < k_; ++i) {  // L y = N a_p
      double sum = rows_[static_cast<size_t>(i)].dot(a_p);
      for (int q = 0; q < i; ++q) sum -= l_[i][q] * y_[q];
      y_[i] = sum / l_[i][i];
    }
    for (int i = k_ - 1; i >= 0; --i) {  // L^T r = y
      double sum = y_[i];
      for (int q = i + 1; q < k_; ++q) sum -= l_[q][i] * r[q];
      r[i] = sum / l_[i][i];
    }
    for (int i = 0; i < k_; ++i) {
      if (!std::isfinite(r[i])) return false;
    }
    last_solve_valid_ = true;
    return true;
  }

  /// Appends a_p, the normal of the last Solve (or any, on an empty set):
  /// L's new row is that solve's y, its diagonal sqrt(|a_p|^2 - |y|^2).
  void Append(const Vector6d& a_p) {
    if (factor_valid_ && (last_solve_valid_ || k_ == 0)) {
      double d2 = a_p.squaredNorm();
      for (int q = 0; q < k_; ++q) {
        l_[k_][q] = y_[q];
        d2 -= y_[q] * y_[q];
      }
      if (d2 > 0.0 && d2 < HUGE_VAL) {
        l_[k_][k_] = std::sqrt(d2);
      } else {
        factor_valid_ = false;
      }
    } else {
      factor_valid_ = false;
    }
    rows_[static_cast<size_t>(k_++)] = a_p;
    last_solve_valid_ = false;
  }

  /// Removes row j; the last row takes its place.
  void Remove(int j) {
    rows_[static_cast<size_t>(j)] = rows_[static_cast<size_t>(k_ - 1)];
    --k_;
    factor_valid_ = k_ == 0;  // the empty factor is valid
    last_solve_valid_ = false;
  }

 private:
  bool Factor() {
    for (int i = 0; i < k_; ++i) {
      for (int j = 0; j <= i; ++j) {
        double sum = rows_[static_cast<size_t>(i)].dot(rows_[static_cast<size_t>(j)]);
        for (int q = 0; q < j; ++q) sum -= l_[i][q] * l_[j][q];
        if (i == j) {
          if (!(sum > 0.0 && sum < HUGE_VAL)) return false;
          l_[i][i] = std::sqrt(sum);
        } else {
          l_[i][j] = sum / l_[j][j];
        }
      }
    }
    factor_valid_ = true;
    return true;
  }

  std::array<Vector6d, 6> rows_;
  double l_[6][6];
  double y_[6];
  int k_ = 0;
  bool factor_valid_ = true;  // the empty factor
  bool last_solve_valid_ = false;
};

}  // namespace

template <int MaxRows>
ProjectionResultN<MaxRows> SolveProjectionQp(const ProjectionQpN<MaxRows>& qp) {
  STEWART_CHECK(qp.m >= 0 && qp.m <= MaxRows, "SolveProjectionQp: m outside [0, MaxRows]");
  ProjectionResultN<MaxRows> res;
  res.mu.setZero();
  res.x = qp.x0;
  std::array<int, 6> active{};
  int num_active = 0;
  std::array<bool, MaxRows> is_active{};
  ActiveNormals normals;  // the rows of `active`, in its order
  // The rows' lengths, once (every iteration scans every inactive row), down
  // the columns of the column-major rows: vectorised.
  Eigen::Matrix<double, MaxRows, 1> row_norm;
  row_norm.head(qp.m) = qp.a.col(0).head(qp.m).cwiseAbs2();
  for (int c = 1; c < 6; ++c) row_norm.head(qp.m) += qp.a.col(c).head(qp.m).cwiseAbs2();
  row_norm.head(qp.m) = row_norm.head(qp.m).cwiseSqrt();

  for (int iter = 0; iter < kMaxIterations<MaxRows>; ++iter) {
    res.iterations = iter + 1;
    // Most violated inactive constraint, scaled by its normal's length.
    int p = -1;
    double worst = 0.0;
    const double x_norm = res.x.norm();
    // Every row's a_i^T x at once: the rows are stored column-major, so this
    // is six vectorised passes down the columns instead of m strided dots.
    Eigen::Matrix<double, MaxRows, 1> ax;
    ax.head(qp.m).noalias() = qp.a.topRows(qp.m) * res.x;
    for (int i = 0; i < qp.m; ++i) {
      if (is_active[static_cast<size_t>(i)]) continue;
      const double norm = row_norm(i);
      const double slack = ax(i) - qp.b(i);
      const double tol = kFeasTol * (std::fabs(qp.b(i)) + norm * x_norm);
      if (slack < -tol && slack / norm < worst) {
        worst = slack / norm;
        p = i;
      }
    }
    if (p < 0) {
      Polish(qp, active, num_active, row_norm, &res);
      return res;
    }

    const Vector6d a_p = qp.a.row(p).transpose();
    double mu_p = 0.0;
    for (;;) {
      double r[6];
      Vector6d z = a_p;
      if (num_active > 0) {
        if (!normals.Solve(a_p, r)) {
          ActiveMatrix n(num_active, 6);
          for (int j = 0; j < num_active; ++j) n.row(j) = normals.row(j).transpose();
          const ActiveGram gram = n * n.transpose();
          const ActiveVector r_ldlt = gram.ldlt().solve(n * a_p);
          for (int j = 0; j < num_active; ++j) r[j] = r_ldlt(j);
        }
        for (int j = 0; j < num_active; ++j) z -= r[j] * normals.row(j);
      }
      const double inf = std::numeric_limits<double>::infinity();
      // Six independent normals span R^6: a seventh is dependent, whatever
      // rounding left in z (this also keeps `active` within its 6 entries).
      const bool dependent =
          num_active == 6 || z.squaredNorm() <= kDependentTol * a_p.squaredNorm();
      const double t1 = dependent ? inf : (qp.b(p) - a_p.dot(res.x)) / z.dot(a_p);
      double t2 = inf;
      int drop = -1;
      for (int j = 0; j < num_active; ++j) {
        if (r[j] > 0.0) {
          const double t = res.mu(active[static_cast<size_t>(j)]) / r[j];
          if (t < t2) {
            t2 = t;
            drop = j;
          }
        }
      }
      if (t1 == inf && t2 == inf) {
        res.status = ProjectionStatus::kInfeasible;
        return res;
      }
      const double t = MinOf(t1, t2);  // t2 is never NaN
      if (!dependent) res.x += t * z;
      for (int j = 0; j < num_active; ++j) {
        double& mu = res.mu(active[static_cast<size_t>(j)]);
        mu = MaxOf(mu - t * r[j], 0.0);
      }
      mu_p += t;
      if (t2 < t1) {
        const int k = active[static_cast<size_t>(drop)];
        res.mu(k) = 0.0;
        is_active[static_cast<size_t>(k)] = false;
        active[static_cast<size_t>(drop)] = active[static_cast<size_t>(num_active - 1)];
        --num_active;
        normals.Remove(drop);
        continue;
      }
      res.mu(p) = mu_p;
      is_active[static_cast<size_t>(p)] = true;
      active[static_cast<size_t>(num_active++)] = p;
      normals.Append(a_p);
      break;
    }
    // Recompute x from the multipliers: keeps rounding from accumulating.
    res.x = qp.x0;
    for (int j = 0; j < num_active; ++j) {
      const int i = active[static_cast<size_t>(j)];
      res.x += res.mu(i) * qp.a.row(i).transpose();
    }
  }
  res.status = ProjectionStatus::kIterationLimit;
  return res;
}

// The two capacities in use: the composed filter's QP and the un-composed one.
template ProjectionResultN<kMaxQpRows> SolveProjectionQp(const ProjectionQpN<kMaxQpRows>&);
template ProjectionResultN<kMaxUncomposedQpRows> SolveProjectionQp(
    const ProjectionQpN<kMaxUncomposedQpRows>&);

}  // namespace stewart::safety
