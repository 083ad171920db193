#include "stewart/common/time_plausibility.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "stewart/test_support/test_clock.h"

namespace stewart {
namespace {

using ::stewart::test::kWallUs;

constexpr int64_t kS = 1'000'000;  // us per s
const TimePlausibilityParams kParams{1.0, 100.0};

TEST(TimePlausibility, FirstMessageAnchorsWithoutReceiveTime) {
  TimePlausibility p(kParams);
  EXPECT_FALSE(p.anchored());
  // Replay has no wall clock: nothing to judge the first time against.
  EXPECT_EQ(p.Check(8'000'000'000'000'000'000, std::nullopt), TimeVerdict::kPlausible);
  EXPECT_EQ(p.Check(0, std::nullopt), TimeVerdict::kPlausible);
  p.Accept(5 * kS, std::nullopt);
  EXPECT_TRUE(p.anchored());
  EXPECT_EQ(p.newest_utime(), 5 * kS);
}

TEST(TimePlausibility, WindowAroundTheNewestAcceptedTime) {
  TimePlausibility p(kParams);
  p.Accept(5 * kS, std::nullopt);
  EXPECT_EQ(p.Check(6 * kS, std::nullopt), TimeVerdict::kPlausible);
  EXPECT_EQ(p.Check(6 * kS + 1, std::nullopt), TimeVerdict::kAheadOfWindow);
  EXPECT_EQ(p.Check(4 * kS, std::nullopt), TimeVerdict::kPlausible);
  EXPECT_EQ(p.Check(4 * kS - 1, std::nullopt), TimeVerdict::kBehindWindow);
  // The attacks: a state near 8e18 us, a sample 1e12 us ahead.
  EXPECT_EQ(p.Check(8'000'000'000'000'000'000, std::nullopt), TimeVerdict::kAheadOfWindow);
  EXPECT_EQ(p.Check(5 * kS + 1'000'000'000'000, std::nullopt), TimeVerdict::kAheadOfWindow);
  // Checking moves nothing.
  EXPECT_EQ(p.newest_utime(), 5 * kS);
}

TEST(TimePlausibility, ExtremeTimesDoNotOverflow) {
  TimePlausibility p(kParams);
  p.Accept(-5 * kS, kWallUs);
  EXPECT_EQ(p.Check(std::numeric_limits<int64_t>::max(), kWallUs), TimeVerdict::kAheadOfWallClock);
  EXPECT_EQ(p.Check(std::numeric_limits<int64_t>::max(), std::nullopt),
            TimeVerdict::kAheadOfWindow);
  EXPECT_EQ(p.Check(std::numeric_limits<int64_t>::min(), kWallUs), TimeVerdict::kBehindWindow);
  TimePlausibility late(kParams);
  late.Accept(std::numeric_limits<int64_t>::max() - 10, std::nullopt);
  EXPECT_EQ(late.Check(std::numeric_limits<int64_t>::min(), std::nullopt),
            TimeVerdict::kBehindWindow);
}

TEST(TimePlausibility, TheNewestTimeNeverMovesBack) {
  TimePlausibility p(kParams);
  p.Accept(5 * kS, std::nullopt);
  p.Accept(5 * kS - 1000, std::nullopt);
  EXPECT_EQ(p.newest_utime(), 5 * kS);
  p.Accept(5 * kS + 1000, std::nullopt);
  EXPECT_EQ(p.newest_utime(), 5 * kS + 1000);
}

TEST(TimePlausibility, AcceptingAnImplausibleTimeIsAProgrammingError) {
  TimePlausibility p(kParams);
  p.Accept(5 * kS, std::nullopt);
  EXPECT_THROW(p.Accept(100 * kS, std::nullopt), std::logic_error);
  EXPECT_EQ(p.newest_utime(), 5 * kS);
}

TEST(TimePlausibility, StackTimeAheadOfTheWallClockIsNeverPlausible) {
  TimePlausibility p(kParams);
  // Before anything was accepted: real time starts at the wall clock,
  // lockstep at 0; neither is ahead of the receive time.
  EXPECT_EQ(p.Check(kWallUs - 3 * kS, kWallUs), TimeVerdict::kPlausible);
  EXPECT_EQ(p.Check(0, kWallUs), TimeVerdict::kPlausible);
  EXPECT_EQ(p.Check(kWallUs + 2 * kS, kWallUs), TimeVerdict::kAheadOfWallClock);
  EXPECT_EQ(p.Check(8'000'000'000'000'000'000, kWallUs), TimeVerdict::kAheadOfWallClock);
}

TEST(TimePlausibility, LockstepRunsFasterThanTheWallClock) {
  // Lockstep at 50x: after 0.1 s of wall time without a message, stack time
  // may have moved 5 s, beyond the window but within 100x.
  TimePlausibility p(kParams);
  p.Accept(20 * kS, kWallUs);
  EXPECT_EQ(p.Check(25 * kS, kWallUs + kS / 10), TimeVerdict::kPlausible);
  EXPECT_EQ(p.Check(20 * kS + 12 * kS, kWallUs + kS / 10), TimeVerdict::kAheadOfWindow);
  // A message 1e12 us ahead 1 ms after the newest: far beyond any rate.
  EXPECT_EQ(p.Check(20 * kS + 1'000'000'000'000, kWallUs + 1000), TimeVerdict::kAheadOfWindow);
  // Without receive times (replay) only the window counts.
  EXPECT_EQ(p.Check(25 * kS, std::nullopt), TimeVerdict::kAheadOfWindow);
}

TEST(TimePlausibility, RealTimePlantRestartIsFollowed) {
  // plant_sim in real time stopped at wall time kWallUs and started again 30 s
  // later: its new stack time is the new wall clock.
  TimePlausibility p(kParams);
  p.Accept(kWallUs - 2000, kWallUs);
  const int64_t restart_wall = kWallUs + 30 * kS;
  EXPECT_EQ(p.Check(restart_wall - 1000, restart_wall), TimeVerdict::kPlausible);
  // Ahead of the wall clock it is not, however long the silence was.
  EXPECT_EQ(p.Check(restart_wall + 5 * kS, restart_wall), TimeVerdict::kAheadOfWallClock);
}

TEST(TimePlausibility, RejectsBadParameters) {
  EXPECT_THROW(TimePlausibility({0.0, 100.0}), std::logic_error);
  EXPECT_THROW(TimePlausibility({1.0, 0.5}), std::logic_error);
  EXPECT_THROW(TimePlausibility({std::numeric_limits<double>::infinity(), 100.0}),
               std::logic_error);
}

TEST(TimePlausibility, VerdictNames) {
  EXPECT_STREQ(ToString(TimeVerdict::kAheadOfWindow), "ahead_of_window");
  EXPECT_STREQ(ToString(TimeVerdict::kBehindWindow), "behind_window");
  EXPECT_STREQ(ToString(TimeVerdict::kAheadOfWallClock), "ahead_of_wall_clock");
}

}  // namespace
}  // namespace stewart
