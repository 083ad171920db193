// A stream's seq numbers tell a gap (messages the log lacks) from a restart
// of its publisher (seq falls back), each at the first message after it.
#include "stewart/common/seq_continuity.h"

#include <gtest/gtest.h>

namespace stewart {
namespace {

TEST(SeqContinuity, ACompleteStreamHasNoEvent) {
  SeqContinuity c;
  for (int k = 0; k < 5; ++k) EXPECT_FALSE(c.Observe("A", k, 1000 * k, 50 + k, k));
  EXPECT_EQ(c.recorded(), 5);
  EXPECT_EQ(c.missing(), 0);
  EXPECT_EQ(c.restarts(), 0);
  EXPECT_TRUE(c.events().empty());
  EXPECT_EQ(c.first_restart(), nullptr);
}

TEST(SeqContinuity, GapsCountTheSkippedMessagesPerStream) {
  SeqContinuity c;
  c.Observe("A", 0, 0, 10, 0);
  c.Observe("B", 2, 0, 11, 1);  // the log lacks B's first two
  const auto gap = c.Observe("A", 4, 4000, 12, 2);
  ASSERT_TRUE(gap);
  EXPECT_EQ(gap->kind, SeqEventKind::kGap);
  EXPECT_EQ(gap->missing, 3);
  EXPECT_EQ(gap->previous_seq, 0);
  EXPECT_EQ(gap->previous_utime, 0);
  EXPECT_EQ(gap->utime, 4000);
  EXPECT_EQ(gap->log_utime, 12);
  EXPECT_EQ(gap->position, 2);
  c.Observe("A", 5, 5000, 13, 3);
  c.Observe("A", 7, 7000, 14, 4);
  EXPECT_EQ(c.streams().at("A").missing, 4);
  EXPECT_EQ(c.streams().at("A").gaps, 2);
  EXPECT_EQ(c.streams().at("B").missing, 2);
  EXPECT_EQ(c.streams().at("B").gaps, 1);
  EXPECT_EQ(c.events().front().stream, "B");
  EXPECT_EQ(c.events().front().previous_seq, -1);
  EXPECT_EQ(c.missing(), 6);
  EXPECT_EQ(c.recorded(), 5);
  EXPECT_EQ(c.restarts(), 0);
}

TEST(SeqContinuity, SeqFallingBackIsARestartNotAGap) {
  SeqContinuity c;
  for (int k = 0; k < 100; ++k) c.Observe("A", k, 1000 * k, k, k);
  const auto restart = c.Observe("A", 0, 100'000, 100, 100);
  ASSERT_TRUE(restart);
  EXPECT_EQ(restart->kind, SeqEventKind::kRestart);
  EXPECT_EQ(restart->previous_seq, 99);
  EXPECT_EQ(restart->missing, 0);
  EXPECT_FALSE(c.Observe("A", 1, 101'000, 101, 101));
  // Restarted again, and the log lacks the new publisher's first 3.
  const auto late = c.Observe("A", 3, 102'000, 102, 102);
  ASSERT_TRUE(late);
  EXPECT_EQ(late->kind, SeqEventKind::kGap);  // seq 3 after 1: indistinguishable from a gap
  const auto again = c.Observe("A", 2, 103'000, 103, 103);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->kind, SeqEventKind::kRestart);
  EXPECT_EQ(again->missing, 2);
  EXPECT_EQ(c.restarts(), 2);
  EXPECT_EQ(c.streams().at("A").missing, 1 + 2);
  ASSERT_NE(c.first_restart(), nullptr);
  EXPECT_EQ(c.first_restart()->position, 100);
  EXPECT_EQ(std::string(ToString(SeqEventKind::kRestart)), "restart");
}

TEST(SeqContinuity, TheSameMessageAgainIsARepeatNotARestart) {
  SeqContinuity c;
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(c.Observe("A", k, 1000 * k, 50 + k, k));
  // A lockstep resend of seq 2 (same utime), answered again: no event.
  EXPECT_FALSE(c.Observe("A", 2, 2000, 300, 3));
  EXPECT_FALSE(c.Observe("A", 3, 3000, 301, 4));
  EXPECT_EQ(c.restarts(), 0);
  EXPECT_EQ(c.missing(), 0);
  EXPECT_EQ(c.streams().at("A").repeats, 1);
  EXPECT_EQ(c.recorded(), 5);
  // The same seq with another time is a publisher that started again.
  const auto restart = c.Observe("A", 3, 9000, 302, 5);
  ASSERT_TRUE(restart);
  EXPECT_EQ(restart->kind, SeqEventKind::kRestart);
}

}  // namespace
}  // namespace stewart
