#include "stewart/node/latency_histogram.h"

#include <gtest/gtest.h>

namespace stewart {
namespace {

TEST(LatencyHistogram, PercentilesOfKnownSamples) {
  LatencyHistogram h;
  EXPECT_EQ(h.Percentile(0.5), 0);
  for (int i = 1; i <= 100; ++i) h.Add(i);  // 1..100 us
  EXPECT_EQ(h.count(), 100);
  EXPECT_EQ(h.Percentile(0.5), 50);
  EXPECT_EQ(h.Percentile(0.99), 99);
  EXPECT_EQ(h.Percentile(1.0), 100);
  EXPECT_EQ(h.max_us(), 100);
}

TEST(LatencyHistogram, OverflowIsReportedNotHidden) {
  LatencyHistogram h;
  for (int i = 0; i < 98; ++i) h.Add(10);
  h.Add(LatencyHistogram::kMaxUs + 5000);
  h.Add(-3);  // a clock step: counted as 0, never a negative index
  EXPECT_EQ(h.Percentile(0.5), 10);
  EXPECT_EQ(h.Percentile(1.0), LatencyHistogram::kMaxUs + 1);
  EXPECT_EQ(h.max_us(), LatencyHistogram::kMaxUs + 5000);
}

}  // namespace
}  // namespace stewart
