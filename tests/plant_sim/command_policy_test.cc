// Real-time hold and timeout fallback, lockstep matching, and a
// library-level lockstep run: the same seed gives byte-identical truth.
#include "stewart/plant_sim/command_policy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "plant_test_util.h"
#include "stewart/model/kinematics.h"
#include "stewart/plant_sim/sensor_model.h"

namespace stewart {
namespace {

using test::Config;

TEST(RealTimeCommandHold, HoldsWhileYoungThenActuatorsOff) {
  RealTimeCommandHold hold(50'000);
  EXPECT_TRUE(hold.Decide(0).actuators_off);  // nothing received yet
  EXPECT_TRUE(hold.Decide(0).timed_out);
  const Vector6d f = Vector6d::Constant(7.0);
  hold.OnCommand(f, 1'000'000, false);
  auto d = hold.Decide(1'050'000);  // exactly the age limit: still applied
  EXPECT_FALSE(d.timed_out);
  EXPECT_FALSE(d.actuators_off);
  EXPECT_EQ(d.force_cmd_n, f);
  EXPECT_EQ(d.age_us, 50'000);
  d = hold.Decide(1'050'001);
  EXPECT_TRUE(d.timed_out);
  EXPECT_TRUE(d.actuators_off);
  EXPECT_EQ(d.force_cmd_n, Vector6d::Zero());
  EXPECT_EQ(d.age_us, -1);
  hold.OnCommand(2 * f, 1'060'000, false);  // recovers on the next command
  EXPECT_EQ(hold.Decide(1'070'000).force_cmd_n, 2 * f);
  EXPECT_FALSE(hold.Decide(1'070'000).actuators_off);
}

// The age is the command's own sample against the tick's, not when it came
// in: a command that arrives now but was computed from a sample 0.4 s old
// (an estimator that was stopped) is never applied.
TEST(RealTimeCommandHold, AnOldCommandArrivingNowIsNotApplied) {
  RealTimeCommandHold hold(50'000);
  hold.OnCommand(Vector6d::Constant(3.0), 600'000, false);
  const auto d = hold.Decide(1'000'000);
  EXPECT_TRUE(d.timed_out);
  EXPECT_TRUE(d.actuators_off);
}

TEST(RealTimeCommandHold, DriveOffTurnsTheActuatorsOffWithoutATimeout) {
  RealTimeCommandHold hold(50'000);
  hold.OnCommand(Vector6d::Zero(), 1000, true);
  const auto d = hold.Decide(2000);
  EXPECT_FALSE(d.timed_out);
  EXPECT_TRUE(d.actuators_off);
  hold.OnCommand(Vector6d::Constant(1.0), 2000, false);
  EXPECT_FALSE(hold.Decide(3000).actuators_off);
  EXPECT_THROW(RealTimeCommandHold(0), std::logic_error);
}

TEST(CommandPolicy, ParsingAndValidation) {
  Vector6d f = Vector6d::Zero();
  EXPECT_EQ(ForceCommandProblem(f), "");
  f(3) = std::nan("");
  EXPECT_EQ(ForceCommandProblem(f), "non_finite_force");
  EXPECT_EQ(MatchLockstepCommand(1000, 1000), LockstepMatch::kAnswer);
  EXPECT_EQ(MatchLockstepCommand(1000, 999), LockstepMatch::kStale);
  EXPECT_EQ(MatchLockstepCommand(1000, 1001), LockstepMatch::kFuture);
}

// The command stream of a real-time run whose commands stop at 0.2 s: the
// plant holds the last command, then after the timeout the legs lock.
TEST(RealTimeCommandHold, TimeoutLocksThePlant) {
  const PlantModel model = test::DefaultModel();
  Plant plant(model, test::OdeOptionsFor("arkode_erk"));
  const Vector6d q0 = Config().plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  RealTimeCommandHold hold(std::llround(Config().plant_sim.command_timeout_s * 1e6));
  const Vector6d push = test::HoldingForce(model.platform, q0) + Vector6d::Constant(2.0);
  Vector6d l_at_timeout = Vector6d::Zero();
  bool timed_out_seen = false;
  for (int k = 0; k < 600; ++k) {
    const double t = k * 1e-3;
    const int64_t utime = k * 1000;
    if (t < 0.2) hold.OnCommand(push, utime, false);
    const auto d = hold.Decide(utime);
    if (d.timed_out && !timed_out_seen) {
      timed_out_seen = true;
      EXPECT_NEAR(t, 0.2 + Config().plant_sim.command_timeout_s, 2e-3);
      l_at_timeout = InverseKinematics(model.platform, plant.q());
    }
    plant.SetActuatorsOff(d.actuators_off);
    if (!d.actuators_off) plant.SetForceCommand(d.force_cmd_n);
    plant.Advance(1e-3);
  }
  ASSERT_TRUE(timed_out_seen);
  EXPECT_TRUE(plant.actuators_off());
  // Moving upwards when power was cut; the lock stops it within ~0.1 mm.
  const Vector6d l_end = InverseKinematics(model.platform, plant.q());
  EXPECT_GT(plant.q()(2), q0(2) + 1e-3);
  EXPECT_LT((l_end - l_at_timeout).cwiseAbs().maxCoeff(), 2e-4);
  EXPECT_LT(plant.qd().norm(), 1e-3);
}

// Lockstep at library level: the sensor sample of tick k is answered by a
// command computed from it (a leg-space PD on the noisy readings), then the
// plant integrates. Two runs with the same seed give identical truth bytes.
std::vector<double> LockstepTruth(unsigned seed) {
  const auto& c = Config();
  const PlantModel model = test::DefaultModel();
  Plant plant(model, test::OdeOptionsFor(c.plant_sim.integrator));
  SensorConfig sc = c.sensors;
  sc.seed = seed;
  SensorModel sensors(sc, c.actuators, c.platform.gravity_mps2);
  const Vector6d q0 = c.plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  const Vector6d hold = test::HoldingForce(model.platform, q0);
  Vector6d l_target = InverseKinematics(model.platform, q0) + Vector6d::Constant(0.01);
  std::vector<double> truth;
  Vector6d l_prev = InverseKinematics(model.platform, q0);
  for (int k = 0; k < 500; ++k) {
    const PlantRates& r = plant.EvaluateRates();
    const SensorReading s =
        sensors.Sample(plant.q(), plant.qd(), r.x_dot.segment<6>(6), r.terms.leg_length_m);
    truth.insert(truth.end(), plant.state().data(), plant.state().data() + 12);
    const Vector6d f =
        hold + 800.0 * (l_target - s.leg_length_m) - 20.0 * (s.leg_length_m - l_prev) / 1e-3;
    l_prev = s.leg_length_m;
    plant.SetForceCommand(f);
    plant.Advance(1e-3);
  }
  return truth;
}

TEST(Lockstep, SameSeedGivesByteIdenticalTruth) {
  const std::vector<double> a = LockstepTruth(7), b = LockstepTruth(7), c = LockstepTruth(8);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_NE(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)), 0);  // noise matters
}

}  // namespace
}  // namespace stewart
