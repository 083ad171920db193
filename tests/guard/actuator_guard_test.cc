// ActuatorGuard: each trip reason, the latch, the operator's reset (refused
// while a reading is outside), and the defaults against the mechanical ends.
#include "stewart/guard/actuator_guard.h"

#include <gtest/gtest.h>

#include <cmath>

#include "stewart/config/default_config.h"
#include "stewart/guard/guard_limits.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

ActuatorGuardLimits Limits() {
  ActuatorGuardLimits l;
  l.min_length_m = 0.385;
  l.max_length_m = 0.585;
  l.stroke_margin_m = 0.010;
  l.speed_cap_mps = 0.05;
  l.force_limit_n = 20.0;
  return l;
}

/// Feeds n samples at 1 kHz from t_us on, leg `leg` moving at v m/s from
/// `l0`, the others at rest at 0.45 m. Returns whether any tripped it.
bool Feed(ActuatorGuard* g, int64_t* t_us, int n, int leg = 0, double l0 = 0.45, double v = 0.0) {
  bool tripped = false;
  for (int k = 0; k < n; ++k) {
    Vector6d l = Vector6d::Constant(0.45);
    l(leg) = l0 + v * k * 1e-3;
    tripped |= g->OnReadings(*t_us, l);
    *t_us += 1000;
  }
  return tripped;
}

TEST(ActuatorGuard, QuietLegsDoNotTrip) {
  ActuatorGuard g(Limits());
  int64_t t = 0;
  EXPECT_FALSE(Feed(&g, &t, 200, 2, 0.45, 0.03));  // 30 mm/s, under the cap
  EXPECT_FALSE(g.tripped());
  EXPECT_FALSE(g.OnForceCommand(Vector6d::Constant(-20.0)));  // at the bound
  EXPECT_NEAR(g.max_speed_mps(), 0.03, 1e-9);
  EXPECT_EQ(g.Reset(), GuardResetResult::kNotTripped);
}

TEST(ActuatorGuard, SpeedTripsLatchesAndResetsOnceAtRest) {
  ActuatorGuard g(Limits());
  int64_t t = 0;
  Feed(&g, &t, 30);
  EXPECT_TRUE(Feed(&g, &t, 40, 3, 0.45, 0.06));
  ASSERT_TRUE(g.tripped());
  EXPECT_EQ(g.trip().reason, GuardTripReason::kSpeed);
  EXPECT_EQ(g.trip().leg, 3);
  EXPECT_GT(g.trip().value, 0.05);
  EXPECT_NE(g.Describe().find("leg 3 speed"), std::string::npos) << g.Describe();
  // Still moving: the reset is refused, the latch holds.
  EXPECT_EQ(g.Reset(), GuardResetResult::kReadingsOutside);
  EXPECT_TRUE(g.tripped());
  // Held by the lead screws: at rest for a full speed window, then cleared.
  Feed(&g, &t, 30, 3, 0.4524);
  EXPECT_EQ(g.Reset(), GuardResetResult::kCleared);
  EXPECT_FALSE(g.tripped());
  EXPECT_EQ(g.trips(), 1);
  EXPECT_EQ(g.resets_cleared(), 1);
  EXPECT_EQ(g.resets_refused(), 1);
  // A reading gap restarts the speed window: no reset on a window that
  // has not seen the leg at rest.
  EXPECT_TRUE(Feed(&g, &t, 40, 3, 0.45, -0.08));
  t += 200'000;
  Feed(&g, &t, 5, 3, 0.45);
  EXPECT_EQ(g.Reset(), GuardResetResult::kReadingsOutside);
}

TEST(ActuatorGuard, StrokeMarginTripsAtBothEndsAndNeedsTheReadingBackInside) {
  ActuatorGuard g(Limits());
  int64_t t = 0;
  EXPECT_FALSE(Feed(&g, &t, 30, 1, 0.3951));  // 10.1 mm from the retracted end
  EXPECT_TRUE(Feed(&g, &t, 1, 1, 0.3949));
  EXPECT_EQ(g.trip().reason, GuardTripReason::kRetractedEnd);
  EXPECT_EQ(g.trip().leg, 1);
  Feed(&g, &t, 30, 1, 0.3949);
  EXPECT_EQ(g.Reset(), GuardResetResult::kReadingsOutside);
  Feed(&g, &t, 30, 1, 0.40);  // moved back inside (by hand: the screws hold it)
  EXPECT_EQ(g.Reset(), GuardResetResult::kCleared);

  ActuatorGuard h(Limits());
  EXPECT_FALSE(Feed(&h, &t, 30, 4, 0.5749));
  EXPECT_TRUE(Feed(&h, &t, 1, 4, 0.5751));
  EXPECT_EQ(h.trip().reason, GuardTripReason::kExtendedEnd);
  EXPECT_EQ(h.trip().leg, 4);
}

TEST(ActuatorGuard, ForceBeyondTheBoundTrips) {
  ActuatorGuard g(Limits());
  Vector6d f = Vector6d::Constant(1.0);
  f(5) = -20.001;
  EXPECT_TRUE(g.OnForceCommand(f));
  EXPECT_EQ(g.trip().reason, GuardTripReason::kForce);
  EXPECT_EQ(g.trip().leg, 5);
  EXPECT_DOUBLE_EQ(g.trip().value, -20.001);
  // A later trip keeps the first reason.
  EXPECT_FALSE(g.OnForceCommand(Vector6d::Constant(1e300)));
  EXPECT_EQ(g.trip().leg, 5);
  ActuatorGuard h(Limits());
  f(5) = NAN;
  EXPECT_TRUE(h.OnForceCommand(f));
  EXPECT_EQ(h.trip().reason, GuardTripReason::kForce);
}

TEST(ActuatorGuard, ImplausibleOrNonFiniteReadingsTrip) {
  ActuatorGuard g(Limits());
  int64_t t = 0;
  Feed(&g, &t, 30);
  EXPECT_TRUE(g.OnReadings(t, Vector6d::Constant(0.45), 0x3F & ~(1U << 2)));
  EXPECT_EQ(g.trip().reason, GuardTripReason::kReading);
  EXPECT_EQ(g.trip().leg, 2);
  ActuatorGuard h(Limits());
  Vector6d l = Vector6d::Constant(0.45);
  l(0) = NAN;
  EXPECT_TRUE(h.OnReadings(0, l));
  EXPECT_EQ(h.Reset(), GuardResetResult::kReadingsOutside);
}

TEST(ActuatorGuard, InconsistentLimitsAreRefused) {
  ActuatorGuardLimits l = Limits();
  l.stroke_margin_m = 0.1;
  EXPECT_THROW(ActuatorGuard{l}, std::logic_error);
  l = Limits();
  l.speed_cap_mps = 0.0;
  EXPECT_THROW(ActuatorGuard{l}, std::logic_error);
}

// The shipped limits: the home pose well inside, and a leg at the cap
// caught before its mechanical end: at the cap, the speed estimate's delay
// (half its 25 ms window) costs less than the margin.
TEST(ActuatorGuard, ShippedLimitsKeepTheHomePoseInsideAndTheEndsFar) {
  const StackConfig& c = DefaultStackConfig();
  const ActuatorGuardLimits l =
      ActuatorGuardLimitsOf(c.guard, c.platform.leg_min_length_m, c.platform.leg_max_length_m);
  const Vector6d home = InverseKinematics(c.platform, c.home_pose);
  for (int i = 0; i < kNumLegs; ++i) {
    EXPECT_GT(home(i) - l.min_length_m, 2.0 * l.stroke_margin_m);
    EXPECT_GT(l.max_length_m - home(i), 2.0 * l.stroke_margin_m);
  }
  EXPECT_GE(l.stroke_margin_m, 0.005);
  EXPECT_GT(l.stroke_margin_m, l.speed_cap_mps * 0.0125);
  EXPECT_GT(l.force_limit_n, 0.0);
  EXPECT_LE(l.force_limit_n, c.actuators.force_limit_n);
}

}  // namespace
}  // namespace stewart
