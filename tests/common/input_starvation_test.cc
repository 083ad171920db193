#include "stewart/common/input_starvation.h"

#include <gtest/gtest.h>

namespace stewart {
namespace {

constexpr int64_t kMs = 1000;
constexpr int64_t kWall = 1'780'000'000'000'000;

TEST(InputStarvation, RejectionsLongerThanTheStaleAgeOnTheWallClock) {
  InputStarvation s(0.02, 1.0);
  EXPECT_FALSE(s.OnRejected(0, kWall));
  EXPECT_FALSE(s.OnRejected(kMs, kWall + 10 * kMs));
  EXPECT_FALSE(s.OnRejected(2 * kMs, kWall + 20 * kMs));  // not longer than 20 ms
  EXPECT_TRUE(s.OnRejected(3 * kMs, kWall + 21 * kMs));
  EXPECT_TRUE(s.starved());
  EXPECT_TRUE(s.OnAccepted());  // ended it
  EXPECT_FALSE(s.starved());
  EXPECT_FALSE(s.OnAccepted());
}

TEST(InputStarvation, OneRejectionAfterASilenceIsNotStarvation) {
  InputStarvation s(0.02, 1.0);
  s.OnAccepted();
  // Seconds without input, then one forged message: nothing says the
  // receiver rejects a stream.
  EXPECT_FALSE(s.OnRejected(8'000'000'000'000'000'000, kWall + 5'000 * kMs));
  EXPECT_FALSE(s.starved());
}

TEST(InputStarvation, AnAcceptedMessageRestartsTheCount) {
  InputStarvation s(0.02, 1.0);
  EXPECT_FALSE(s.OnRejected(0, kWall));
  s.OnAccepted();
  EXPECT_FALSE(s.OnRejected(kMs, kWall + 15 * kMs));
  EXPECT_FALSE(s.OnRejected(2 * kMs, kWall + 30 * kMs));  // 15 ms since this run began
}

TEST(InputStarvation, WithoutReceiveTimesAConsistentStreamOfRejectedTimes) {
  InputStarvation s(0.02, 1.0);
  for (int64_t k = 0; k <= 20; ++k) EXPECT_FALSE(s.OnRejected(k * kMs, std::nullopt)) << k;
  EXPECT_TRUE(s.OnRejected(21 * kMs, std::nullopt));
}

TEST(InputStarvation, WithoutReceiveTimesFarOffMessagesNeverMakeAStream) {
  InputStarvation s(0.02, 1.0);
  // A forged time and a real one alternate: no run of consistent times
  // spans the stale age, so one forged message never starves a receiver.
  for (int64_t k = 0; k < 100; ++k) {
    EXPECT_FALSE(s.OnRejected(k % 2 ? 8'000'000'000'000'000'000 : k * kMs, std::nullopt)) << k;
  }
}

}  // namespace
}  // namespace stewart
