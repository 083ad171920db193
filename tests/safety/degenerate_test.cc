// Degenerate and hostile inputs: defined, finite output and a flag.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "safety_test_support.h"
#include "stewart/model/kinematics.h"
#include "stewart/safety/clp_reference_qp.h"
#include "stewart/safety/two_constraint_qp.h"

namespace stewart::safety::test {
namespace {

TEST(Degenerate, AtRestThePositionNormalIsZeroAndOnlyVelocityActs) {
  // Upper limits only (the paper's set): with a lower and an upper limit on
  // one axis at rest, their LSE weights are equal and their rates cancel
  // (docs/safety.md), so the condition would not act at this instant.
  SafetyFilter filter(DefaultConfig().platform, DefaultConfig().safety, DefaultConfig().actuators);
  // Accelerates along +x: the (then smallest-margin) xd limit must act.
  const auto [q, qd, f_des, t] = AtRestPushedAlongX(20.0);
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(q, qd, f_des, &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_EQ(d.barriers.g_p, Vector6d::Zero());
  EXPECT_GT(d.barriers.h_pos, 0.0);
  EXPECT_EQ(d.filter_case, FilterCase::kVelocity);
  EXPECT_FALSE(d.infeasible);
  EXPECT_EQ(d.mu_p, 0.0);
}

// Outside the position set, steered back by the recovery barriers: flagged,
// the position group left out, feasible, and never F_des itself.
void ExpectSteeredBackFromOutside(const SafetyDiagnostics& d, const std::string& where) {
  EXPECT_TRUE(d.barriers.outside_position_set) << where;
  EXPECT_TRUE(d.flags & kFlagOutsideSafeSet) << where;
  EXPECT_FALSE(d.infeasible) << where;
  EXPECT_FALSE(d.flags & kFlagFallback) << where;
  EXPECT_TRUE(d.flags & kFlagFilterActive) << where;
}

// At rest outside a position limit the energy barrier's F gradient -H^T qd
// vanishes: its condition would demand an unbounded force (or none at all).
// The filter leaves the position group out there and the recovery barrier
// h_r = -xd + phi(0.11 - x) pulls the platform back, with a force that stays
// bounded and continuous as the velocity noise goes to zero.
TEST(Degenerate, AtRestOutsideThePositionSetSteersBackAndIsFlagged) {
  for (const SafetyVariant variant : {SafetyVariant::kClosedForm, SafetyVariant::kUncomposed}) {
    SafetyFilter filter = MakeRichFilter(false, variant);
    Vector6d q = DefaultConfig().home_pose;
    q(0) = 0.12;  // 10 mm beyond x <= 0.11
    const VelocityBarrierSpec* recovery = nullptr;
    for (int i = 0; i < filter.constraints().num_velocity; ++i) {
      const VelocityBarrierSpec& v = filter.constraints().velocity[static_cast<size_t>(i)];
      if (v.name == "x_upper_recovery") recovery = &v;
    }
    ASSERT_NE(recovery, nullptr);
    EXPECT_GT(recovery->recovery_speed, 0.0);
    // The recovery condition asks -xdd >= -phi(-10 mm) = v_r tanh(kappa 10 mm
    // / v_r) at rest (the group's unit class-K rate, docs/safety.md).
    double phi = 0.0, slope = 0.0;
    RecoveryTarget(*recovery, -0.01, &phi, &slope);
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 1.0);
    Vector6d f_at_rest = Vector6d::Zero();
    for (const double qd_size : {0.0, 1e-9, 1e-6, 1e-4}) {
      Vector6d qd;
      for (int i = 0; i < 6; ++i) qd(i) = qd_size * noise(rng);
      const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, qd);
      SafetyDiagnostics d;
      const Vector6d f = filter.Step(q, qd, HoverForce(q), &d);
      const std::string where = ToString(variant) + " |qd| ~ " + std::to_string(qd_size);
      ASSERT_TRUE(f.allFinite()) << where;
      ExpectSteeredBackFromOutside(d, where);
      const Vector6d qdd = ForwardDynamics(
          t, f + LegViscousFriction(filter.leg_friction_nspm(), t.H.transpose() * qd));
      EXPECT_LT(qdd(0), 0.999 * phi) << where;
      EXPECT_LE(f.cwiseAbs().maxCoeff(), 100.0) << where;
      if (qd_size == 0.0) f_at_rest = f;
      // Continuous in qd: velocity noise does not kick the command.
      EXPECT_LT((f - f_at_rest).cwiseAbs().maxCoeff(), 1e3 * qd_size + 1e-9) << where;
    }
  }
}

// The same for a leg beyond its stroke band (the stroke drawn in by
// leg_stroke.margin_m): the energy barrier of the leg cannot act at rest, the
// leg's recovery barrier h_r = ld_i + phi(l_i - l_lower) steers it back
// (Ldd_i = H(:, i)^T qdd + (J_l-dot qd)_i > 0), with the shipped config
// (each barrier checked), bounded and continuous in qd.
Vector6d PoseWithLegsBelowTheBand(const StackConfig& config, double beyond_m) {
  const double lower = LegStrokeBandOf(config.platform, config.safety.leg_stroke).lower_m;
  Vector6d q = config.home_pose;
  while (InverseKinematics(config.platform, q).minCoeff() > lower - beyond_m) q(2) -= 1e-5;
  return q;
}

TEST(Degenerate, AtRestWithALegBeyondItsBandSteersItBackAndIsFlagged) {
  const StackConfig& config = DefaultConfig();
  const Vector6d q = PoseWithLegsBelowTheBand(config, 0.002);
  const double lower = LegStrokeBandOf(config.platform, config.safety.leg_stroke).lower_m;
  const Vector6d leg_length = InverseKinematics(config.platform, q);
  ASSERT_TRUE(LegLengthsWithinStroke(config.platform, leg_length));
  for (const SafetyVariant variant : {SafetyVariant::kClosedForm, SafetyVariant::kUncomposed}) {
    SafetyConfig s = config.safety;
    s.variant = variant;
    SafetyFilter filter(config.platform, s, config.actuators);
    std::mt19937 rng(6);
    std::normal_distribution<double> noise(0.0, 1.0);
    Vector6d f_at_rest = Vector6d::Zero();
    for (const double qd_size : {0.0, 1e-9, 1e-6, 1e-4}) {
      Vector6d qd;
      for (int i = 0; i < 6; ++i) qd(i) = qd_size * noise(rng);
      const DynamicsTerms t = EvaluateDynamics(config.platform, q, qd);
      SafetyDiagnostics d;
      const Vector6d f = filter.Step(q, qd, HoverForce(q), &d);
      const std::string where = ToString(variant) + " |qd| ~ " + std::to_string(qd_size);
      ASSERT_TRUE(f.allFinite()) << where;
      ExpectSteeredBackFromOutside(d, where);
      const Vector6d qdd = ForwardDynamics(
          t, f + LegViscousFriction(filter.leg_friction_nspm(), t.H.transpose() * qd));
      const Vector6d leg_accel = t.H.transpose() * qdd + t.leg_bias_accel_mps2;
      for (int i = 0; i < kNumLegs; ++i) {
        if (leg_length(i) >= lower) continue;
        const VelocityBarrierSpec& r =
            filter.constraints().velocity[static_cast<size_t>(6 + 2 * i)];
        ASSERT_EQ(r.name, "leg" + std::to_string(i) + "_lower_recovery");
        double phi = 0.0, slope = 0.0;
        RecoveryTarget(r, leg_length(i) - lower, &phi, &slope);
        // Its own condition (each barrier checked): dh_r >= -gamma h_r with
        // h_r = ld + phi, dh_r = Ldd + phi' ld; at rest Ldd >= -gamma phi > 0.
        const double ld = t.H.col(i).dot(qd);
        const double gamma = s.velocity_rate_per_s;
        EXPECT_GT(leg_accel(i) + slope * ld, -gamma * (ld + phi) + 1e-3 * gamma * phi)
            << where << " leg " << i;
        EXPECT_GT(leg_accel(i), 0.0) << where << " leg " << i;
      }
      EXPECT_LE(f.cwiseAbs().maxCoeff(), config.actuators.force_limit_n + 1e-9) << where;
      if (qd_size == 0.0) f_at_rest = f;
      EXPECT_LT((f - f_at_rest).cwiseAbs().maxCoeff(), 1e3 * qd_size + 1e-9) << where;
    }
  }
}

// Inside the band a leg's recovery barrier is out of the group: wherever
// every leg is inside, the filter answers bit for bit as without them.
TEST(Degenerate, InsideTheBandTheLegsRecoveryBarriersChangeNothing) {
  SafetyConfig without = RichSafetyConfig();
  without.leg_stroke.recovery = false;
  const SafetyFilter with_legs = MakeRichFilter(true);
  without.force_limits_enabled = true;
  const SafetyFilter axes_only(DefaultConfig().platform, without, DefaultConfig().actuators);
  const double lower = LegStrokeBandOf(DefaultConfig().platform, without.leg_stroke).lower_m;
  const double upper = LegStrokeBandOf(DefaultConfig().platform, without.leg_stroke).upper_m;
  std::mt19937 rng(8);
  int inside = 0, outside = 0;
  for (int n = 0; n < 2000; ++n) {
    const auto [q, qd, f_des, terms] = RandomFilterInput(&rng);
    SafetyDiagnostics d_with, d_without;
    const Vector6d f_with = with_legs.StepWithTerms(terms, q, qd, f_des, &d_with);
    const Vector6d f_without = axes_only.StepWithTerms(terms, q, qd, f_des, &d_without);
    const bool legs_inside =
        (terms.leg_length_m.array() >= lower).all() && (terms.leg_length_m.array() <= upper).all();
    int active_leg_rows = 0;
    for (int i = 0; i < with_legs.constraints().num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      if (with_legs.constraints().velocity[k].source == PositionSource::kLegLength &&
          d_with.barriers.velocity_active[k]) {
        ++active_leg_rows;
      } else if (!d_with.barriers.velocity_active[k]) {
        EXPECT_EQ(d_with.barriers.w_velocity[k], 0.0);
      }
    }
    if (legs_inside) {
      ++inside;
      EXPECT_EQ(active_leg_rows, 0) << "sample " << n;
      EXPECT_EQ(f_with, f_without) << "sample " << n;
    } else {
      ++outside;
      EXPECT_GT(active_leg_rows, 0) << "sample " << n;
    }
  }
  EXPECT_GT(inside, 1000);
  std::printf("[leg recovery] %d states with every leg inside the band, %d with one beyond\n",
              inside, outside);
}

TEST(Degenerate, WithoutTheLegsRecoveryALegBeyondItsBandIsInfeasibleAndFlagged) {
  const StackConfig& config = DefaultConfig();
  SafetyConfig s = config.safety;
  s.leg_stroke.recovery = false;
  SafetyFilter filter(config.platform, s, config.actuators);
  const Vector6d q = PoseWithLegsBelowTheBand(config, 0.002);
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(q, Vector6d::Zero(), HoverForce(q), &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_FALSE(d.barriers.outside_position_set);
  EXPECT_TRUE(d.flags & kFlagOutsideSafeSet);
  EXPECT_TRUE(d.infeasible);
}

TEST(Degenerate, WithoutRecoveryBarriersAtRestOutsideIsInfeasibleAndFlagged) {
  SafetyConfig s = RichSafetyConfig();
  s.recovery_gain_per_s = 0.0;
  SafetyFilter filter(DefaultConfig().platform, s, DefaultConfig().actuators);
  Vector6d q = DefaultConfig().home_pose;
  q(0) = 0.12;  // beyond x <= 0.11: h_pos < 0 and g_p = 0
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(q, Vector6d::Zero(), HoverForce(q), &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_LT(d.barriers.psi_p, 0.0);
  EXPECT_FALSE(d.barriers.outside_position_set);
  EXPECT_TRUE(d.flags & kFlagOutsideSafeSet);
  EXPECT_TRUE(d.infeasible);
  EXPECT_TRUE(d.flags & kFlagInfeasible);
  EXPECT_EQ(d.filter_case, FilterCase::kInfeasible);
  // The velocity condition is still enforced by the fallback.
  EXPECT_GE(d.barriers.psi_v + d.barriers.g_v.dot(f - HoverForce(q)), -1e-12);
}

TEST(Degenerate, ParallelNormals) {
  TwoConstraintProblem p;
  p.has_p = p.has_v = true;
  p.g_p << 1, 2, 0, 0, 0, 0;
  p.g_v = 3.0 * p.g_p;  // same direction: the tighter one binds
  p.psi_p = -1.0;
  p.psi_v = -6.0;
  TwoConstraintSolution s = SolveExactKkt(p);
  EXPECT_TRUE(s.feasible);
  EXPECT_EQ(s.filter_case, FilterCase::kVelocity);
  EXPECT_NEAR(p.psi_p + p.g_p.dot(s.mu_v * p.g_v), 1.0, 1e-12);

  p.g_v = -p.g_p;  // opposite: a slab -psi_p <= g_p.d <= psi_v
  p.psi_v = 2.0;
  s = SolveExactKkt(p);
  EXPECT_TRUE(s.feasible);
  EXPECT_EQ(s.filter_case, FilterCase::kPosition);
  p.psi_v = -0.5;  // empty slab
  s = SolveExactKkt(p);
  EXPECT_FALSE(s.feasible);
  EXPECT_EQ(s.filter_case, FilterCase::kInfeasible);
  // Fallback keeps the position condition exactly.
  const TwoConstraintSolution fb = SolveInfeasibleFallback(p);
  EXPECT_NEAR(p.psi_p + p.g_p.dot(fb.mu_p * p.g_p), 0.0, 1e-12);
  EXPECT_FALSE(fb.feasible);
}

TEST(Degenerate, NearlyParallelNormalsStayFiniteAndMatchTheReference) {
  for (double angle : {1e-3, 1e-5, 1e-7, 1e-9}) {
    TwoConstraintProblem p;
    p.has_p = p.has_v = true;
    p.g_p << 1, 0, 0, 0, 0, 0;
    p.g_v << std::cos(angle), std::sin(angle), 0, 0, 0, 0;
    p.psi_p = -1.0;
    p.psi_v = -1.0 - angle;  // both active for a non-degenerate angle
    const TwoConstraintSolution s = SolveExactKkt(p);
    const Vector6d d = s.mu_p * p.g_p + s.mu_v * p.g_v;
    EXPECT_TRUE(d.allFinite());
    if (s.feasible) {
      EXPECT_GE(p.psi_p + p.g_p.dot(d), -1e-9);
      EXPECT_GE(p.psi_v + p.g_v.dot(d), -1e-9 * (1 + d.norm()));
    }
  }
}

// Closed form and un-composed QP, each unlimited and force-limited.
TEST(Degenerate, NanOrInfInAnyInputGivesTheFlaggedSafeStop) {
  for (const SafetyVariant variant : {SafetyVariant::kClosedForm, SafetyVariant::kUncomposed}) {
    for (const bool force_limits : {false, true}) {
      SafetyFilter filter = MakeRichFilter(force_limits, variant);
      const Vector6d q = DefaultConfig().home_pose;
      const Vector6d qd = Vector6d::Constant(0.001);
      const Vector6d f_des = HoverForce(q);
      const std::string where = ToString(variant) + (force_limits ? " force-limited" : "");
      for (double bad :
           {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        for (int which = 0; which < 3; ++which) {
          for (int i = 0; i < 6; ++i) {
            Vector6d in[3] = {q, qd, f_des};
            in[which](i) = bad;
            SafetyDiagnostics d;
            const Vector6d f = filter.Step(in[0], in[1], in[2], &d);
            EXPECT_TRUE(f.allFinite()) << where << " " << which << " " << i;
            EXPECT_TRUE(d.flags & kFlagInvalidInput) << where;
            EXPECT_TRUE(d.flags & kFlagFallback) << where;
            EXPECT_EQ(d.filter_case, FilterCase::kFallback) << where;
            EXPECT_TRUE(std::isfinite(d.correction_norm)) << where;
            EXPECT_TRUE(std::isfinite(d.barriers.psi_p) && std::isfinite(d.barriers.psi_v));
            EXPECT_EQ(d.mu_p, 0.0) << where;
            EXPECT_EQ(d.mu_v, 0.0) << where;
            for (double mu : d.mu_position) EXPECT_EQ(mu, 0.0) << where;
            for (double mu : d.mu_velocity) EXPECT_EQ(mu, 0.0) << where;
            if (which == 2 && !force_limits) {
              // q, qd valid: the hold brake decelerates, qdd = -qd / stop_time.
              const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, qd);
              EXPECT_LE((ForwardDynamics(t, f) + qd / DefaultConfig().safety.stop_time_s).norm(),
                        1e-9)
                  << where;
            }
          }
        }
      }
      // Beyond kMaxInputForceN: rejected as invalid, safe stop.
      SafetyDiagnostics d;
      const Vector6d f = filter.Step(q, qd, Vector6d::Constant(1e300), &d);
      EXPECT_TRUE(f.allFinite()) << where;
      EXPECT_TRUE(d.flags & kFlagInvalidInput) << where;
      EXPECT_LT(f.norm(), 1e3) << where;
    }
  }
}

TEST(Degenerate, HugeNominalForce) {
  SafetyFilter filter = MakeRichFilter();
  const Vector6d q = DefaultConfig().home_pose;
  SafetyDiagnostics d;
  // Large but representable: filtered normally, strongly corrected.
  Vector6d f = filter.Step(q, Vector6d::Constant(0.001), Vector6d::Constant(1e6), &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_FALSE(d.flags & kFlagInvalidInput);
  EXPECT_TRUE(d.flags & kFlagFilterActive);
  EXPECT_GE(d.barriers.psi_v + d.barriers.g_v.dot(f - d.f_des), -1e-9 * 1e6);
  // Beyond kMaxInputForceN: rejected as invalid, safe stop.
  f = filter.Step(q, Vector6d::Constant(0.001), Vector6d::Constant(1e300), &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_TRUE(d.flags & kFlagInvalidInput);
  EXPECT_LT(f.norm(), 1e3);
  // Its correction is huge and finite (the plain norm overflowed to Inf).
  EXPECT_TRUE(std::isfinite(d.correction_norm));
  EXPECT_GT(d.correction_norm, 2e300);
}

TEST(Degenerate, ForceLimitsThatMakeTheConditionsInfeasibleAreReported) {
  SafetyConfig s = RichSafetyConfig();
  s.force_limits_enabled = true;
  // Only a lower z velocity limit: falling violates it at once.
  s.velocity_limits = {{2, -0.010, std::nullopt, 2.0}};
  ActuatorConfig weak = DefaultConfig().actuators;
  weak.force_limit_n = 0.5;  // cannot even hold the platform up
  SafetyFilter filter(DefaultConfig().platform, s, weak);
  const Vector6d q = DefaultConfig().home_pose;
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(q, Vector6d::Zero(), HoverForce(q), &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_TRUE(d.infeasible);
  EXPECT_TRUE(d.flags & kFlagInfeasible);
  EXPECT_LE(f.cwiseAbs().maxCoeff(), 0.5 + 1e-12);
}

// Below a lower z limit with force limits too small to lift the platform:
// the recovery condition cannot be met within the box. The answer misses it
// as little as the box allows (at the box's best, within the relaxation's
// tolerance). Without the velocity row, the nearest point of the box to a
// nominal that lets the platform drop would be that nominal itself.
TEST(Degenerate, InfeasibleOutsideTheSetTheBoxDoesItsBestForTheRecovery) {
  ActuatorConfig weak = DefaultConfig().actuators;
  weak.force_limit_n = 1.0;  // hovering takes 3.8 N per leg
  // The composed closed form alone, with the per-barrier check that hands a
  // broken barrier to the un-composed QP (as shipped), and the un-composed
  // variant.
  struct Case {
    SafetyVariant variant;
    bool check_each_barrier;
  };
  for (const Case& k :
       {Case{SafetyVariant::kClosedForm, false}, Case{SafetyVariant::kClosedForm, true},
        Case{SafetyVariant::kUncomposed, false}}) {
    SafetyConfig s = RichSafetyConfig();
    s.force_limits_enabled = true;
    s.variant = k.variant;
    s.check_each_barrier = k.check_each_barrier;
    const SafetyFilter filter(DefaultConfig().platform, s, weak);
    const std::string where = ToString(k.variant) + (k.check_each_barrier ? " checked" : "");
    const PositionBarrierSpec* z_lower = nullptr;
    for (int i = 0; i < filter.constraints().num_position; ++i) {
      const PositionBarrierSpec& p = filter.constraints().position[static_cast<size_t>(i)];
      if (p.source == PositionSource::kAxis && p.index == 2 && p.sign > 0.0) z_lower = &p;
    }
    ASSERT_NE(z_lower, nullptr);
    Vector6d q = DefaultConfig().home_pose;
    q(2) = z_lower->limit - 0.005;  // 5 mm below it, at rest
    const Vector6d qd = Vector6d::Zero();
    const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, qd);
    // The nominal lets the platform drop: a tenth of the hover force.
    const Vector6d f_des = 0.1 * HoverForce(q);
    ASSERT_LT(f_des.cwiseAbs().maxCoeff(), weak.force_limit_n);
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(t, q, qd, f_des, &d);
    ASSERT_TRUE(f.allFinite()) << where;
    EXPECT_TRUE(d.barriers.outside_position_set) << where;
    EXPECT_TRUE(d.infeasible) << where;
    EXPECT_TRUE(d.flags & kFlagInfeasible) << where;
    EXPECT_FALSE(d.flags & kFlagFallback) << where;
    EXPECT_LE(f.cwiseAbs().maxCoeff(), weak.force_limit_n + 1e-9) << where;
    // Psi_v is affine in F with gradient g_v: over the box alone (no position
    // row outside the set) its best is at F_i = limit sign(g_v,i).
    const Vector6d& g_v = d.barriers.g_v;
    const auto psi_v_at = [&](const Vector6d& force) {
      return d.barriers.psi_v + g_v.dot(force - d.f_nominal);
    };
    const Vector6d best = weak.force_limit_n * g_v.array().sign().matrix();
    ASSERT_LT(psi_v_at(best), 0.0) << "the recovery must be out of the box's reach";
    const auto zdd = [&](const Vector6d& force) { return ForwardDynamics(t, force)(2); };
    if (k.variant == SafetyVariant::kClosedForm && !k.check_each_barrier) {
      // The bisection's guarantee, and the QP's rounding.
      const double shortfall = -psi_v_at(f_des);
      EXPECT_GT(psi_v_at(f), psi_v_at(best) - 1.01 * kRelaxationRelTol * shortfall - 1e-9);
    }
    // It lifts (nearly) as hard as the box allows.
    EXPECT_GT(zdd(f), zdd(f_des) + 1.0) << where;
    EXPECT_GT(zdd(f), zdd(best) - 0.05 * std::fabs(zdd(best))) << where;
    std::printf(
        "[box best] %s: Psi_v: F_des %.4g, answer %.4g, box best %.4g m/s^2; "
        "zdd %.4g -> %.4g m/s^2 (box best %.4g)\n",
        where.c_str(), psi_v_at(f_des), psi_v_at(f), psi_v_at(best), zdd(f_des), zdd(f), zdd(best));
  }
}

// The answer to `qp` without the rows `skip` marks, F = T y: the position
// rows' and the box's answer, whose shortfall bounds the least relaxation.
template <int MaxRows, typename Skip>
Vector6d ForceWithoutRows(const ProjectionQpN<MaxRows>& qp, const Matrix6d& map, Skip skip) {
  ProjectionQpN<MaxRows> kept;
  kept.x0 = qp.x0;
  for (int r = 0; r < qp.m; ++r) {
    if (skip(r)) continue;
    kept.a.row(kept.m) = qp.a.row(r);
    kept.b(kept.m++) = qp.b(r);
  }
  const ProjectionResultN<MaxRows> result = SolveProjectionQp(kept);
  EXPECT_EQ(result.status, ProjectionStatus::kOptimal);
  return SafetyFilter::ForceFromQpSolution(map, result.x);
}

// Every other input moved up to 10 mm (or 10 mrad) beyond one of the
// filter's axis position limits, drawn at random: half the states outside the
// position set, where the velocity rows hold the recovery barriers.
FilterInput MaybeBeyondAnAxisLimit(const SafetyFilter& filter, FilterInput x, std::mt19937* rng) {
  if (std::uniform_int_distribution<int>(0, 1)(*rng) == 0) return x;
  std::vector<const PositionBarrierSpec*> axes;
  for (int i = 0; i < filter.constraints().num_position; ++i) {
    const PositionBarrierSpec& p = filter.constraints().position[static_cast<size_t>(i)];
    if (p.source == PositionSource::kAxis) axes.push_back(&p);
  }
  const PositionBarrierSpec& p =
      *axes[std::uniform_int_distribution<size_t>(0, axes.size() - 1)(*rng)];
  // h = sign (q - limit) < 0.
  x.q(p.index) = p.limit - p.sign * std::uniform_real_distribution<double>(1e-4, 0.01)(*rng);
  x.terms = EvaluateDynamics(DefaultConfig().platform, x.q, x.qd);
  return x;
}

constexpr double kWeakForceLimitN = 1.0;  // a quarter of the hover force: often infeasible

SafetyFilter WeakBoxFilter(SafetyVariant variant) {
  SafetyConfig s = RichSafetyConfig();
  s.force_limits_enabled = true;
  s.variant = variant;
  ActuatorConfig weak = DefaultConfig().actuators;
  weak.force_limit_n = kWeakForceLimitN;
  return SafetyFilter(DefaultConfig().platform, s, weak);
}

// Vertex `corner` (0..63, one bit per leg) of the box |F_i| <= limit_n.
Vector6d BoxVertex(int corner, double limit_n) {
  Vector6d v;
  for (int i = 0; i < kNumLegs; ++i) v(i) = (corner >> i & 1) ? limit_n : -limit_n;
  return v;
}

// Calls check(n, x, f, d) for each step of `filter` that is infeasible and
// not the safe stop, among `samples` random inputs (half of them beyond an
// axis limit), once its answer is finite and inside the box.
template <typename Check>
void ForEachInfeasibleStep(const SafetyFilter& filter, int samples, Check&& check) {
  std::mt19937 rng(61);
  for (int n = 0; n < samples; ++n) {
    const FilterInput x = MaybeBeyondAnAxisLimit(filter, RandomFilterInput(&rng), &rng);
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &d);
    ASSERT_TRUE(f.allFinite()) << "sample " << n;
    if (!d.infeasible || (d.flags & kFlagFallback)) continue;
    EXPECT_LE(f.cwiseAbs().maxCoeff(), kWeakForceLimitN * (1.0 + 1e-9)) << "sample " << n;
    check(n, x, f, d);
  }
}

// Wherever the force-limited conditions have no common point: outside the
// position set the answer misses the velocity condition by no more than any
// vertex of the box (the bisection's tolerance and rounding aside), checked
// against points the QP did not see; inside it the velocity row is dropped
// and the answer is the position row's and the box's (measured better on the
// P-16P legs, docs/safety.md).
TEST(Degenerate, InfeasibleForceLimitedStepsMissTheVelocityConditionLeastOutside) {
  const SafetyFilter filter = WeakBoxFilter(SafetyVariant::kClosedForm);
  int outside = 0, inside = 0;
  ForEachInfeasibleStep(
      filter, 8000,
      [&](int n, const FilterInput& x, const Vector6d& f, const SafetyDiagnostics& d) {
        const BarrierEvaluation& b = d.barriers;
        const auto psi_v_at = [&](const Vector6d& force) {
          return b.psi_v + b.g_v.dot(force - d.f_nominal);
        };
        const Matrix6d map = filter.MetricMap(x.terms);
        ProjectionQp qp;
        QpRows rows;
        filter.BuildQp(map, b, d.f_nominal, &qp, &rows);
        const Vector6d f_without = ForceWithoutRows(qp, map, [&](int r) { return r == rows.v; });
        if (!b.outside_position_set) {
          ++inside;
          EXPECT_LT((f - f_without).norm(), 1e-6 * (1.0 + f_without.norm())) << "sample " << n;
          return;
        }
        ++outside;
        const double shortfall = -psi_v_at(f_without);
        ASSERT_GT(shortfall, 0.0) << "sample " << n;
        const double scale = std::fabs(b.psi_v) + b.g_v.norm() * (f - d.f_nominal).norm() + 1.0;
        for (int corner = 0; corner < 64; ++corner) {
          const Vector6d v = BoxVertex(corner, kWeakForceLimitN);
          EXPECT_GE(psi_v_at(f), psi_v_at(v) - 1.01 * kRelaxationRelTol * shortfall - 1e-9 * scale)
              << "sample " << n << " corner " << corner;
        }
      });
  EXPECT_GT(outside, 30);
  EXPECT_GT(inside, 50);
  std::printf("[least relaxation] infeasible force-limited states: %d outside, %d inside\n",
              outside, inside);
}

// The un-composed variant, outside the position set, relaxes all its
// velocity rows by one distance in the metric: the worst miss of its answer
// is no larger than that of any vertex of the box. Inside, it drops them.
TEST(Degenerate, InfeasibleUncomposedStepsMissTheirWorstVelocityRowLeastOutside) {
  const SafetyFilter filter = WeakBoxFilter(SafetyVariant::kUncomposed);
  int outside = 0, inside = 0;
  ForEachInfeasibleStep(
      filter, 4000,
      [&](int n, const FilterInput& x, const Vector6d& f, const SafetyDiagnostics& d) {
        const Matrix6d map = filter.MetricMap(x.terms);
        UncomposedQp qp;
        UncomposedQpRows rows;
        filter.BuildUncomposedQp(x.terms, x.qd, map, d.barriers, d.f_nominal, &qp, &rows);
        const auto slack = [&](int row, const Vector6d& force) {
          return qp.a.row(row).dot(map.partialPivLu().solve(force)) - qp.b(row);
        };
        const auto worst_miss = [&](const Vector6d& force) {
          double miss = 0.0;
          for (int i = 0; i < filter.constraints().num_velocity; ++i) {
            const int row = rows.velocity_row[static_cast<size_t>(i)];
            if (row >= 0) miss = std::fmax(miss, -slack(row, force));
          }
          return miss;
        };
        const auto is_velocity_row = [&](int r) {
          for (int i = 0; i < filter.constraints().num_velocity; ++i) {
            if (rows.velocity_row[static_cast<size_t>(i)] == r) return true;
          }
          return false;
        };
        const Vector6d f_without = ForceWithoutRows(qp, map, is_velocity_row);
        if (!d.barriers.outside_position_set) {
          ++inside;
          EXPECT_LT((f - f_without).norm(), 1e-6 * (1.0 + f_without.norm())) << "sample " << n;
          return;
        }
        ++outside;
        const double shortfall = worst_miss(f_without);
        const double miss = worst_miss(f);
        for (int corner = 0; corner < 64; ++corner) {
          const Vector6d v = BoxVertex(corner, kWeakForceLimitN);
          EXPECT_LE(miss, worst_miss(v) + 1.01 * kRelaxationRelTol * shortfall + 1e-9 * shortfall)
              << "sample " << n << " corner " << corner;
        }
      });
  EXPECT_GT(outside, 50);
  EXPECT_GT(inside, 50);
  std::printf(
      "[least relaxation, un-composed] infeasible force-limited states: %d outside, %d "
      "inside\n",
      outside, inside);
}

// The QP-based variants return F_des itself, bit for bit, when no row acts:
// not T T^-1 F_des, which differs by rounding and would read as an
// intervention (active time, correction norm).
TEST(Degenerate, NoActiveRowPassesFDesExactly) {
  for (const SafetyVariant variant : {SafetyVariant::kClosedForm, SafetyVariant::kUncomposed}) {
    for (const bool force_limits : {false, true}) {
      SafetyFilter filter = MakeRichFilter(force_limits, variant);
      std::mt19937 rng(53);
      int untouched = 0;
      for (int n = 0; n < 2000; ++n) {
        const FilterInput x = RandomFilterInput(&rng);
        SafetyDiagnostics d;
        const Vector6d f = filter.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &d);
        if (d.filter_case != FilterCase::kNone || (d.mu_force.array() != 0.0).any()) continue;
        ++untouched;
        EXPECT_TRUE(f == x.f_des) << ToString(variant) << " " << force_limits << " sample " << n;
        EXPECT_EQ(d.correction_norm, 0.0);
      }
      EXPECT_GT(untouched, 100) << ToString(variant) << " " << force_limits;
    }
  }
}

}  // namespace
}  // namespace stewart::safety::test
