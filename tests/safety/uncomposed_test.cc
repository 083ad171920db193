// Variant uncomposed (every barrier its own condition, no LSE): KKT on the
// output, every single-barrier condition met, agreement with the composed
// filter as k grows where one barrier per group matters, degenerate inputs.
// The comparison with Clp is uncomposed_reference_test.cc.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "stewart/model/kinematics.h"
#include "uncomposed_support.h"

namespace stewart::safety::test {
namespace {

SafetyConfig UncomposedConfig(bool force_limits, CorrectionMetric metric) {
  SafetyConfig s = RichSafetyConfig();
  s.variant = SafetyVariant::kUncomposed;
  s.force_limits_enabled = force_limits;
  s.correction_metric = metric;
  return s;
}

// Sums over the single-barrier rows for the stationarity check.
struct Stationarity {
  Vector6d sum_mu_n = Vector6d::Zero();
  double sum_abs_mu_n = 0.0;  // rounding in the stationarity residual grows with it
  int active = 0;             ///< rows of the last group checked with mu > 0
};

// One group's single-barrier conditions (position or velocity) at F_des and F*.
template <typename Spec, size_t N>
struct GroupKkt {
  int count;
  const std::array<double, N>& mu;
  const std::array<double, N>& psi_des;
  const std::array<double, N>& psi_f;
  const std::array<Vector6d, N>& n_des;
  const std::array<Spec, N>& specs;
  double scale;
  double tol_floor;  ///< inside the tolerance's parentheses
};

// Dual and primal feasibility and complementary slackness of each barrier of
// the group; adds its rows to the stationarity sums and returns sum_i mu_i.
template <typename Spec, size_t N>
double CheckGroupKkt(const GroupKkt<Spec, N>& g, int n, Stationarity* sums) {
  double mu_sum = 0.0;
  sums->active = 0;
  for (int i = 0; i < g.count; ++i) {
    const size_t k = static_cast<size_t>(i);
    const double mu = g.mu[k];
    const double tol =
        1e-10 * (std::fabs(g.psi_des[k]) + g.n_des[k].norm() * g.scale + g.tol_floor);
    EXPECT_GE(mu, 0.0) << "sample " << n;
    // Every single-barrier condition holds at F*, and only tight ones push.
    EXPECT_GE(g.psi_f[k], -tol) << "sample " << n << " " << g.specs[k].name;
    EXPECT_LE(std::fabs(mu * g.psi_f[k]), mu * tol + 1e-300) << "sample " << n;
    sums->sum_mu_n += mu * g.n_des[k];
    sums->sum_abs_mu_n += mu * g.n_des[k].norm();
    mu_sum += mu;
    sums->active += mu > 0.0 ? 1 : 0;
  }
  return mu_sum;
}

// KKT of min (F - F_des)^T W (F - F_des) s.t. Psi_i(F) >= 0 for every barrier
// [, |F_i| <= F_max], checked on the output with normals and conditions
// computed independently (uncomposed_support.h).
void CheckKkt(bool force_limits, CorrectionMetric metric, double position_margin,
              double velocity_margin) {
  SafetyConfig config = UncomposedConfig(force_limits, metric);
  config.position_robust_margin_w = position_margin;
  config.velocity_robust_margin_mps2 = velocity_margin;
  SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
  ASSERT_GT(filter.leg_friction_nspm(), 0.0);  // the friction shift is exercised
  const double f_max = DefaultConfig().actuators.force_limit_n;
  std::mt19937 rng(force_limits ? 31 : 37);
  int checked = 0, active = 0, multi_velocity = 0;
  for (int n = 0; n < 4000; ++n) {
    // One state in four near a position limit (uncomposed_support.h): the
    // position rows bind there, alone or with nearly parallel velocity rows.
    NearOneLimit x;
    if (n % 4 != 3 || !DrawNearPositionLimit(filter, n % 8 == 3 ? 1e-5 : 2e-3, &rng, &x)) {
      x = RandomFilterInput(&rng);
    }
    const auto& [q, qd, f_des, terms] = x;
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(terms, q, qd, f_des, &d);
    ASSERT_TRUE(f.allFinite());
    EXPECT_EQ(d.variant, SafetyVariant::kUncomposed);
    if (d.infeasible) continue;
    ++checked;
    const SingleBarrierConditions at_des =
        EvaluateSingleBarrierConditions(filter, q, qd, terms, f_des);
    const SingleBarrierConditions at_f = EvaluateSingleBarrierConditions(filter, q, qd, terms, f);
    const double scale = f.norm() + f_des.norm() + 1.0;
    Stationarity sums;
    const double mu_p = CheckGroupKkt(
        GroupKkt<PositionBarrierSpec, kMaxPositionBarriers>{
            at_f.num_position, d.mu_position, at_des.psi_position, at_f.psi_position,
            at_des.n_position, filter.constraints().position, scale, 1e-12},
        n, &sums);
    const double mu_v = CheckGroupKkt(
        GroupKkt<VelocityBarrierSpec, kMaxVelocityBarriers>{
            at_f.num_velocity, d.mu_velocity, at_des.psi_velocity, at_f.psi_velocity,
            at_des.n_velocity, filter.constraints().velocity, scale, 0.0},
        n, &sums);
    const Vector6d& sum_mu_n = sums.sum_mu_n;
    const double sum_abs_mu_n = sums.sum_abs_mu_n;
    const int velocity_active = sums.active;
    if (velocity_active > 1) ++multi_velocity;
    // The diagnostics' group multipliers are the sums of the rows'.
    EXPECT_NEAR(d.mu_p, mu_p, 1e-12 * mu_p);
    EXPECT_NEAR(d.mu_v, mu_v, 1e-12 * mu_v);
    if (mu_p > 0.0 || mu_v > 0.0) ++active;
    const FilterCase expected_case = mu_p > 0.0
                                         ? (mu_v > 0.0 ? FilterCase::kBoth : FilterCase::kPosition)
                                         : (mu_v > 0.0 ? FilterCase::kVelocity : FilterCase::kNone);
    EXPECT_EQ(d.filter_case, expected_case) << "sample " << n;
    // Stationarity in the metric: F - F_des = W^-1 (sum_i mu_i n_i - mu_force).
    const Matrix6d t = filter.MetricMap(terms);
    const Matrix6d w_inv = t * t.transpose();
    const Vector6d residual = f - f_des - w_inv * (sum_mu_n - d.mu_force);
    EXPECT_LE(residual.norm(), 1e-10 * (scale + w_inv.norm() * (sum_abs_mu_n + d.mu_force.norm())))
        << "sample " << n;
    ExpectForceLimitsKkt(f, d.mu_force, force_limits, f_max, n);
  }
  EXPECT_GT(checked, 3500);
  EXPECT_GT(active, 1000);
  // Several velocity rows at once: what the composition cannot represent.
  EXPECT_GT(multi_velocity, 50);
}

TEST(Uncomposed, KktForceMetric) { CheckKkt(false, CorrectionMetric::kForce, 0.0, 0.0); }
TEST(Uncomposed, KktAccelerationMetric) {
  CheckKkt(false, CorrectionMetric::kAcceleration, 0.0, 0.0);
}
TEST(Uncomposed, KktTaskAccelerationMetric) {
  CheckKkt(false, CorrectionMetric::kTaskAcceleration, 0.0, 0.0);
}
TEST(Uncomposed, KktForceLimited) { CheckKkt(true, CorrectionMetric::kForce, 0.0, 0.0); }
TEST(Uncomposed, KktForceLimitedTaskAccelerationMetric) {
  CheckKkt(true, CorrectionMetric::kTaskAcceleration, 0.0, 0.0);
}
TEST(Uncomposed, KktForceLimitedAccelerationMetric) {
  CheckKkt(true, CorrectionMetric::kAcceleration, 0.0, 0.0);
}
// The robust margins shift every row by its group's delta.
TEST(Uncomposed, KktWithRobustMargins) {
  CheckKkt(false, CorrectionMetric::kAcceleration, 1e-4, 2e-3);
}

// There the composed condition tends to that barrier's own as k grows
// (h_c -> alpha_i h_i, w_i -> 1), so the two filters must agree.
// Run on the paper's barriers (recovery barriers off: every case occurs
// often) and with the recovery barriers (they bind near a position limit, so
// fewer states have one clearly smallest margin per group).
TEST(Uncomposed, AgreesWithTheComposedFilterAsKGrows) {
  const PlatformParams& platform = DefaultConfig().platform;
  for (const bool recovery : {false, true}) {
    for (CorrectionMetric metric : {CorrectionMetric::kForce, CorrectionMetric::kAcceleration}) {
      SafetyConfig base = UncomposedConfig(false, metric);
      if (!recovery) base.recovery_gain_per_s = 0.0;
      SCOPED_TRACE(recovery ? "with recovery barriers" : "paper's barriers");
      SafetyFilter uncomposed(platform, base, DefaultConfig().actuators);
      // (k_position 1/J, k_velocity s/m), from soft to far sharper than shipped.
      const std::array<std::pair<double, double>, 5> ks = {
          {{2e3, 3e2}, {2e4, 3e3}, {2e5, 3e4}, {2e6, 3e5}, {2e7, 3e6}}};
      std::array<double, 5> sum_err{};
      std::array<SafetyFilter, 5> composed = [&] {
        auto make = [&](size_t i) {
          SafetyConfig s = base;
          s.variant = SafetyVariant::kClosedForm;
          s.k_position = ks[i].first;
          s.k_velocity = ks[i].second;
          return SafetyFilter(platform, s, DefaultConfig().actuators);
        };
        return std::array<SafetyFilter, 5>{make(0), make(1), make(2), make(3), make(4)};
      }();
      const ConstraintSet& c = uncomposed.constraints();
      std::mt19937 rng(metric == CorrectionMetric::kForce ? 41 : 43);
      std::array<int, 4> cases{};
      int selected = 0;
      for (int n = 0; n < 30000 && selected < 1500; ++n) {
        NearOneLimit x;
        // Velocity barrier alone; position barrier alone; both (the other
        // axes' motion turns the position normal away from the velocity one).
        // Most velocity-type draws bind a position barrier too, so they get
        // two slots of four.
        const bool drawn = n % 4 < 2    ? DrawNearOneLimit(&rng, &x)
                           : n % 4 == 2 ? DrawNearPositionLimit(uncomposed, 1e-5, &rng, &x)
                                        : DrawNearPositionLimit(uncomposed, 2e-3, &rng, &x);
        if (!drawn) continue;
        SafetyDiagnostics du;
        const Vector6d fu = uncomposed.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &du);
        if (du.infeasible) continue;
        // The smallest scaled margin of each group by a clear gap (k_max * gap
        // > 746: the other weights underflow to exactly 0), and only it may
        // carry a multiplier.
        // Rows out of the group (a leg's recovery barrier inside its band,
        // `active` false) take no part.
        auto single = [](const double* alpha_h, const double* mu, int count, double gap,
                         const bool* active) {
          auto in = [&](int i) { return active == nullptr || active[i]; };
          int smallest = -1;
          for (int i = 0; i < count; ++i) {
            if (in(i) && (smallest < 0 || alpha_h[i] < alpha_h[smallest])) smallest = i;
          }
          for (int i = 0; i < count; ++i) {
            if (i == smallest || !in(i)) continue;
            if (alpha_h[i] - alpha_h[smallest] < gap || mu[i] != 0.0) return false;
          }
          return true;
        };
        if (!single(du.barriers.alpha_h_position.data(), du.mu_position.data(), c.num_position,
                    1e-4, nullptr) ||
            !single(du.barriers.alpha_h_velocity.data(), du.mu_velocity.data(), c.num_velocity,
                    5e-4, du.barriers.velocity_active.data())) {
          continue;
        }
        // The other rows must have slack at F* (the composed QP at large k
        // does not contain them).
        const SingleBarrierConditions at_f =
            EvaluateSingleBarrierConditions(uncomposed, x.q, x.qd, x.terms, fu);
        bool slack = true;
        for (int i = 0; i < c.num_position; ++i) {
          const size_t k = static_cast<size_t>(i);
          if (du.mu_position[k] == 0.0 && at_f.psi_position[k] < 1e-6) slack = false;
        }
        for (int i = 0; i < c.num_velocity; ++i) {
          const size_t k = static_cast<size_t>(i);
          if (!du.barriers.velocity_active[k]) continue;  // no row
          if (du.mu_velocity[k] == 0.0 && at_f.psi_velocity[k] < 1e-6) slack = false;
        }
        if (!slack) continue;
        ++selected;
        ++cases[static_cast<size_t>(du.filter_case)];
        for (size_t i = 0; i < ks.size(); ++i) {
          SafetyDiagnostics dc;
          const Vector6d fc = composed[i].StepWithTerms(x.terms, x.q, x.qd, x.f_des, &dc);
          const double err = RelativeError(fc, fu);
          sum_err[i] += err;
          if (i + 1 == ks.size()) {
            EXPECT_LE(err, 1e-9) << "sample " << n << "\ncomposed   " << fc.transpose()
                                 << "\nuncomposed " << fu.transpose();
            EXPECT_EQ(dc.filter_case, du.filter_case) << "sample " << n;
          }
        }
      }
      std::printf(
          "%s metric: %d states (cases none %d pos %d vel %d both %d); mean rel. difference "
          "composed vs uncomposed for (k_position, k_velocity) = ",
          ToString(metric).c_str(), selected, cases[0], cases[1], cases[2], cases[3]);
      for (size_t i = 0; i < ks.size(); ++i) {
        std::printf("(%.0e, %.0e): %.3g%s", ks[i].first, ks[i].second, sum_err[i] / selected,
                    i + 1 < ks.size() ? ", " : "\n");
      }
      EXPECT_GE(selected, recovery ? 200 : 500);
      EXPECT_GT(cases[1], 20);
      EXPECT_GT(cases[2], 20);
      if (!recovery) {
        EXPECT_GT(cases[3], 20);
      }
      // The difference shrinks with k, from visible to rounding.
      for (size_t i = 1; i < ks.size(); ++i) {
        EXPECT_TRUE(sum_err[i] < sum_err[i - 1] || sum_err[i] / selected < 1e-12)
            << "k level " << i;
      }
      if (!recovery) {
        EXPECT_GT(sum_err[0] / selected, 1e-4);
      }
    }
  }
}

TEST(UncomposedDegenerate, AtRestOnlyVelocityRowsAct) {
  // qd = 0: every position row has a zero normal (left out, all met inside).
  SafetyFilter filter = MakeRichFilter(false, SafetyVariant::kUncomposed);
  const auto [q, qd, f_des, t] = AtRestPushedAlongX(20.0);
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(q, qd, f_des, &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_FALSE(d.infeasible);
  EXPECT_EQ(d.filter_case, FilterCase::kVelocity);
  EXPECT_EQ(d.mu_p, 0.0);
  const SingleBarrierConditions at_f =
      EvaluateSingleBarrierConditions(filter, q, Vector6d::Zero(), t, f);
  for (int i = 0; i < at_f.num_velocity; ++i) {
    EXPECT_GE(at_f.psi_velocity[static_cast<size_t>(i)], -1e-9);
  }
  // Only xd_upper is pushed (every leg inside its band: the legs' recovery
  // rows are not in the QP).
  for (int i = 0; i < at_f.num_velocity; ++i) {
    const size_t k = static_cast<size_t>(i);
    const bool x_upper = filter.constraints().velocity[k].name == "xd_upper";
    EXPECT_EQ(d.mu_velocity[k] > 0.0, x_upper);
    if (filter.constraints().velocity[k].source == PositionSource::kLegLength) {
      EXPECT_FALSE(d.barriers.velocity_active[k]);
    }
  }
}

TEST(UncomposedDegenerate, AtRestOutsideThePositionSetMeetsEveryVelocityRow) {
  Vector6d q = DefaultConfig().home_pose;
  q(0) = 0.12;  // beyond x <= 0.11 at rest: the position rows are left out
  const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, Vector6d::Zero());
  // Hover, and a push along +x that the velocity and recovery rows must stop.
  for (const Vector6d& f_des :
       {HoverForce(q), Vector6d(InverseDynamics(t, Vector6d::Unit(0) * 5.0))}) {
    for (const bool force_limits : {false, true}) {
      SafetyFilter filter = MakeRichFilter(force_limits, SafetyVariant::kUncomposed);
      SafetyDiagnostics d;
      const Vector6d f = filter.Step(q, Vector6d::Zero(), f_des, &d);
      EXPECT_TRUE(f.allFinite());
      EXPECT_FALSE(d.infeasible);
      EXPECT_FALSE(d.flags & kFlagFallback);
      EXPECT_TRUE(d.flags & kFlagOutsideSafeSet);
      // Every velocity row, the recovery rows among them, holds exactly.
      const SingleBarrierConditions at_f =
          EvaluateSingleBarrierConditions(filter, q, Vector6d::Zero(), t, f);
      for (int i = 0; i < at_f.num_velocity; ++i) {
        EXPECT_GE(at_f.psi_velocity[static_cast<size_t>(i)], -1e-9) << i;
      }
      EXPECT_LE(f.cwiseAbs().maxCoeff(), DefaultConfig().actuators.force_limit_n + 1e-9);
    }
  }
}

TEST(UncomposedDegenerate, EmptyVelocitySlabKeepsThePositionRows) {
  // A robust margin wider than the velocity ranges: the lower and upper rows
  // of one axis cannot both hold (qdd_x <= u - xd - delta, >= l - xd + delta).
  SafetyConfig config = UncomposedConfig(false, CorrectionMetric::kAcceleration);
  config.velocity_robust_margin_mps2 = 1.0;
  SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
  std::mt19937 rng(47);
  for (int n = 0; n < 200; ++n) {
    const auto [q, qd, f_des, terms] = RandomFilterInput(&rng);
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(terms, q, qd, f_des, &d);
    ASSERT_TRUE(f.allFinite());
    EXPECT_TRUE(d.infeasible);
    EXPECT_EQ(d.filter_case, FilterCase::kInfeasible);
    EXPECT_TRUE(d.flags & kFlagInfeasible);
    EXPECT_FALSE(d.flags & kFlagFallback);
    const SingleBarrierConditions at_f = EvaluateSingleBarrierConditions(filter, q, qd, terms, f);
    const double scale = f.norm() + f_des.norm() + 1.0;
    for (int i = 0; i < at_f.num_position; ++i) {
      const size_t k = static_cast<size_t>(i);
      EXPECT_GE(at_f.psi_position[k], -1e-10 * (1e-3 + at_f.n_position[k].norm() * scale))
          << "sample " << n;
    }
  }
}

// A violated position row with a zero normal (at rest, 10 mm beyond x <=
// 0.11, no recovery barriers to leave the position group out): no force can
// meet it. The answer is the documented safe stop, flagged infeasible and
// fallback, as the closed form's last resort and the force-limited variant
// (before, the unlimited variant applied the velocity rows alone, flagged
// only infeasible).
TEST(UncomposedDegenerate, PositionRowsNoForceCanMeetGiveTheFlaggedSafeStop) {
  SafetyConfig config = RichSafetyConfig();
  config.variant = SafetyVariant::kUncomposed;
  config.recovery_gain_per_s = 0.0;
  Vector6d q = DefaultConfig().home_pose;
  q(0) = 0.12;
  const Vector6d qd = Vector6d::Zero();
  const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, qd);
  for (const bool force_limits : {false, true}) {
    config.force_limits_enabled = force_limits;
    SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
    for (const Vector6d& f_des :
         {HoverForce(q), Vector6d(InverseDynamics(t, Vector6d::Unit(0) * 5.0))}) {
      SafetyDiagnostics d;
      const Vector6d f = filter.Step(q, qd, f_des, &d);
      const std::string where = force_limits ? "force-limited" : "unlimited";
      EXPECT_FALSE(d.barriers.outside_position_set) << where;
      EXPECT_TRUE(d.infeasible) << where;
      EXPECT_EQ(d.filter_case, FilterCase::kFallback) << where;
      EXPECT_TRUE(d.flags & kFlagFallback) << where;
      EXPECT_TRUE(d.flags & kFlagInfeasible) << where;
      EXPECT_FALSE(d.flags & kFlagInvalidInput) << where;
      EXPECT_EQ(d.mu_p, 0.0) << where;
      EXPECT_EQ(d.mu_v, 0.0) << where;
      SafetyDiagnostics stop;
      EXPECT_EQ(f, filter.SafeStopCommand(q, qd, &stop)) << where;
      // The same command as the closed form's safe stop at this state.
      SafetyConfig closed = config;
      closed.variant = SafetyVariant::kClosedForm;
      SafetyFilter closed_form(DefaultConfig().platform, closed, DefaultConfig().actuators);
      EXPECT_EQ(f, closed_form.SafeStopCommand(q, qd, &stop)) << where;
    }
  }
}

// NaN/Inf inputs: Degenerate.NanOrInfInAnyInputGivesTheFlaggedSafeStop covers this variant.

TEST(UncomposedDegenerate, HugeNominalForceIsCorrectedAndFinite) {
  SafetyFilter filter = MakeRichFilter(false, SafetyVariant::kUncomposed);
  const Vector6d q = DefaultConfig().home_pose;
  const Vector6d qd = Vector6d::Constant(0.001);
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(q, qd, Vector6d::Constant(1e6), &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_FALSE(d.flags & kFlagInvalidInput);
  EXPECT_TRUE(d.flags & kFlagFilterActive);
  const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, qd);
  const SingleBarrierConditions at_f = EvaluateSingleBarrierConditions(filter, q, qd, t, f);
  for (int i = 0; i < at_f.num_velocity; ++i) {
    EXPECT_GE(at_f.psi_velocity[static_cast<size_t>(i)], -1e-9 * 1e6);
  }
}

TEST(Uncomposed, VariantParsesAndNeedsNoReferenceSolver) {
  EXPECT_EQ(ParseSafetyVariant("uncomposed"), SafetyVariant::kUncomposed);
  EXPECT_EQ(ToString(SafetyVariant::kUncomposed), "uncomposed");
  SafetyConfig s = DefaultConfig().safety;
  s.variant = SafetyVariant::kUncomposed;
  EXPECT_NO_THROW(SafetyFilter(DefaultConfig().platform, s, DefaultConfig().actuators));
}

}  // namespace
}  // namespace stewart::safety::test
