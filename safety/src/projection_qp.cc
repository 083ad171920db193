#include "stewart/safety/projection_qp.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace stewart::safety {
namespace {

constexpr double kFeasTol = 1e-12;       // relative to |b| + |a| |x|
constexpr double kDependentTol = 1e-20;  // ||z||^2 vs ||a_p||^2: a_p in span
constexpr int kMaxIterations = 60;

using ActiveMatrix = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6>;
using ActiveVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using ActiveGram = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

// Re-solves the final active set directly so the active constraints hold to
// rounding, whatever the path the iteration took.
void Polish(const ProjectionQp& qp, const std::array<int, 6>& active, int num_active,
            ProjectionResult* res) {
  if (num_active == 0) return;
  ActiveMatrix n(num_active, 6);
  ActiveVector rhs(num_active);
  for (int j = 0; j < num_active; ++j) {
    const int i = active[static_cast<size_t>(j)];
    n.row(j) = qp.a.row(i);
    rhs(j) = qp.b(i) - qp.a.row(i).dot(qp.x0);
  }
  const ActiveGram gram = n * n.transpose();
  const ActiveVector mu = gram.ldlt().solve(rhs);
  if (!mu.allFinite() || (mu.array() < 0.0).any()) return;
  Vector6d x = qp.x0 + n.transpose() * mu;
  res->x = x;
  for (int j = 0; j < num_active; ++j) res->mu(active[static_cast<size_t>(j)]) = mu(j);
}

}  // namespace

ProjectionResult SolveProjectionQp(const ProjectionQp& qp) {
  ProjectionResult res;
  res.mu.setZero();
  res.x = qp.x0;
  std::array<int, 6> active{};
  int num_active = 0;
  std::array<bool, kMaxQpRows> is_active{};

  for (int iter = 0; iter < kMaxIterations; ++iter) {
    res.iterations = iter + 1;
    // Most violated inactive constraint, scaled by its normal's length.
    int p = -1;
    double worst = 0.0;
    for (int i = 0; i < qp.m; ++i) {
      if (is_active[static_cast<size_t>(i)]) continue;
      const double norm = qp.a.row(i).norm();
      const double slack = qp.a.row(i).dot(res.x) - qp.b(i);
      const double tol = kFeasTol * (std::fabs(qp.b(i)) + norm * res.x.norm());
      if (slack < -tol && slack / norm < worst) {
        worst = slack / norm;
        p = i;
      }
    }
    if (p < 0) {
      Polish(qp, active, num_active, &res);
      return res;
    }

    const Vector6d a_p = qp.a.row(p).transpose();
    double mu_p = 0.0;
    for (;;) {
      ActiveMatrix n(num_active, 6);
      for (int j = 0; j < num_active; ++j) n.row(j) = qp.a.row(active[static_cast<size_t>(j)]);
      ActiveVector r(num_active);
      Vector6d z = a_p;
      if (num_active > 0) {
        const ActiveGram gram = n * n.transpose();
        r = gram.ldlt().solve(n * a_p);
        z -= n.transpose() * r;
      }
      const double inf = std::numeric_limits<double>::infinity();
      const bool dependent = z.squaredNorm() <= kDependentTol * a_p.squaredNorm();
      const double t1 = dependent ? inf : (qp.b(p) - a_p.dot(res.x)) / z.dot(a_p);
      double t2 = inf;
      int drop = -1;
      for (int j = 0; j < num_active; ++j) {
        if (r(j) > 0.0) {
          const double t = res.mu(active[static_cast<size_t>(j)]) / r(j);
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
      const double t = std::fmin(t1, t2);
      if (!dependent) res.x += t * z;
      for (int j = 0; j < num_active; ++j) {
        double& mu = res.mu(active[static_cast<size_t>(j)]);
        mu = std::fmax(mu - t * r(j), 0.0);
      }
      mu_p += t;
      if (t2 < t1) {
        const int k = active[static_cast<size_t>(drop)];
        res.mu(k) = 0.0;
        is_active[static_cast<size_t>(k)] = false;
        active[static_cast<size_t>(drop)] = active[static_cast<size_t>(num_active - 1)];
        --num_active;
        continue;
      }
      res.mu(p) = mu_p;
      is_active[static_cast<size_t>(p)] = true;
      active[static_cast<size_t>(num_active++)] = p;
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

}  // namespace stewart::safety
