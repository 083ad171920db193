#include "stewart/common/input_starvation.h"

#include <gtest/gtest.h>

#include "stewart/test_support/test_clock.h"

namespace stewart {
namespace {

using ::stewart::test::kMsUs;
using ::stewart::test::kWallUs;

TEST(InputStarvation, RejectionsLongerThanTheStaleAgeOnTheWallClock) {
  InputStarvation s(0.02, 1.0);
  EXPECT_FALSE(s.OnRejected(0, kWallUs));
  EXPECT_FALSE(s.OnRejected(kMsUs, kWallUs + 10 * kMsUs));
  EXPECT_FALSE(s.OnRejected(2 * kMsUs, kWallUs + 20 * kMsUs));  // not longer than 20 ms
  EXPECT_TRUE(s.OnRejected(3 * kMsUs, kWallUs + 21 * kMsUs));
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
  EXPECT_FALSE(s.OnRejected(8'000'000'000'000'000'000, kWallUs + 5'000 * kMsUs));
  EXPECT_FALSE(s.starved());
}

TEST(InputStarvation, AnAcceptedMessageRestartsTheCount) {
  InputStarvation s(0.02, 1.0);
  EXPECT_FALSE(s.OnRejected(0, kWallUs));
  s.OnAccepted();
  EXPECT_FALSE(s.OnRejected(kMsUs, kWallUs + 15 * kMsUs));
  EXPECT_FALSE(s.OnRejected(2 * kMsUs, kWallUs + 30 * kMsUs));  // 15 ms since this run began
}

TEST(InputStarvation, WithoutReceiveTimesAConsistentStreamOfRejectedTimes) {
  InputStarvation s(0.02, 1.0);
  for (int64_t k = 0; k <= 20; ++k) EXPECT_FALSE(s.OnRejected(k * kMsUs, std::nullopt)) << k;
  EXPECT_TRUE(s.OnRejected(21 * kMsUs, std::nullopt));
}

TEST(InputStarvation, WithoutReceiveTimesFarOffMessagesNeverMakeAStream) {
  InputStarvation s(0.02, 1.0);
  // A forged time and a real one alternate: no run of consistent times
  // spans the stale age, so one forged message never starves a receiver.
  for (int64_t k = 0; k < 100; ++k) {
    EXPECT_FALSE(s.OnRejected(k % 2 ? 8'000'000'000'000'000'000 : k * kMsUs, std::nullopt)) << k;
  }
}

}  // namespace
}  // namespace stewart
