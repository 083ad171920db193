// The link stewart_netrelay puts between two groups: delay, jitter and loss
// as configured, order kept without jitter, nothing dropped silently.
#include "stewart/node/impaired_link.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace stewart {
namespace {

std::vector<uint8_t> Datagram(uint8_t tag) { return {tag, 1, 2, 3}; }

TEST(ImpairedLink, WithoutJitterEveryDatagramLeavesAfterTheDelayInItsOrder) {
  ImpairedLink link({/*delay_ms=*/5.0, /*jitter_ms=*/0.0, /*loss=*/0.0}, 7);
  for (uint8_t i = 0; i < 10; ++i) {
    const auto d = Datagram(i);
    link.Offer(d.data(), d.size(), 1000 * i);  // one per ms
  }
  ASSERT_TRUE(link.NextDueUs().has_value());
  EXPECT_EQ(*link.NextDueUs(), 5000);
  std::vector<uint8_t> order;
  const auto take = [&](const std::vector<uint8_t>& d) { order.push_back(d[0]); };
  EXPECT_EQ(link.DeliverDue(4999, take), 0) << "nothing leaves before its delay";
  EXPECT_EQ(link.DeliverDue(7000, take), 3);  // offered at 0, 1, 2 ms
  EXPECT_EQ(link.DeliverDue(100000, take), 7);
  EXPECT_EQ(order, (std::vector<uint8_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(link.counters().delivered, 10);
  EXPECT_FALSE(link.NextDueUs().has_value());
}

TEST(ImpairedLink, JitterStaysWithinItsBoundAndLossNearItsRate) {
  constexpr int kN = 20000;
  ImpairedLink link({/*delay_ms=*/2.0, /*jitter_ms=*/1.0, /*loss=*/0.1}, 11);
  const auto d = Datagram(0);
  for (int i = 0; i < kN; ++i) link.Offer(d.data(), d.size(), 0);
  int64_t first_due = *link.NextDueUs();
  EXPECT_GE(first_due, 2000);
  EXPECT_EQ(link.DeliverDue(1999, [](const std::vector<uint8_t>&) {}), 0);
  const int delivered = link.DeliverDue(3000, [](const std::vector<uint8_t>&) {});
  EXPECT_FALSE(link.NextDueUs().has_value()) << "a datagram was held beyond delay + jitter";
  EXPECT_EQ(delivered + link.counters().lost, kN);
  // 10 % of 20000: 2000 +- 5 sigma (sigma = 42).
  EXPECT_NEAR(static_cast<double>(link.counters().lost), 2000.0, 215.0);
}

TEST(ImpairedLink, AFullQueueDropsAndCountsInsteadOfGrowing) {
  ImpairedLink link({/*delay_ms=*/1000.0, 0.0, 0.0}, 1, /*max_datagrams=*/4, /*max_bytes=*/1 << 20);
  const auto d = Datagram(0);
  for (int i = 0; i < 10; ++i) link.Offer(d.data(), d.size(), 0);
  EXPECT_EQ(link.counters().offered, 10);
  EXPECT_EQ(link.counters().overflow, 6);
  EXPECT_EQ(link.counters().max_queued, 4);
}

TEST(ImpairedLink, ImpossibleSettingsAreRefusedNamingTheField) {
  try {
    ImpairedLink link({1.0, 0.0, 1.5}, 1);
    FAIL() << "a loss of 1.5 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("loss"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ValidateLinkImpairment({-1.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(ValidateLinkImpairment({0.0, std::numeric_limits<double>::infinity(), 0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace stewart
