#include "stewart/common/input_time_check.h"

#include <gtest/gtest.h>

#include "stewart/test_support/test_clock.h"

namespace stewart {
namespace {

using ::stewart::test::kMsUs;
using ::stewart::test::kWallUs;

constexpr int64_t kForged = 8'000'000'000'000'000'000;

TEST(InputTimeCheck, AnImplausibleSourceMessageIsCountedByName) {
  HealthCounters counters("safety");
  InputTimeCheck check({1.0, 100.0}, "state", 0.02, &counters);
  ASSERT_TRUE(check.CheckSource(10 * kMsUs, 10 * kMsUs, std::nullopt));
  check.SourceAccepted(10 * kMsUs, std::nullopt);
  EXPECT_FALSE(check.CheckSource(kForged, kForged, std::nullopt));
  EXPECT_EQ(counters.rejected_inputs(), 1);
  EXPECT_EQ(counters.counter("rejected_state_time_implausible"), 1);
  EXPECT_NE(counters.last_error().find("lcm.time_window_s"), std::string::npos)
      << counters.last_error();
  EXPECT_EQ(check.plausibility().newest_utime(), 10 * kMsUs);
  // sample_utime is checked as well.
  EXPECT_FALSE(check.CheckSource(11 * kMsUs, kForged, std::nullopt));
  EXPECT_EQ(counters.counter("rejected_state_time_implausible"), 2);
}

TEST(InputTimeCheck, OtherInputsAreJudgedAgainstTheSourceAndNeverMoveIt) {
  HealthCounters counters("safety");
  InputTimeCheck check({1.0, 100.0}, "state", 0.02, &counters);
  check.SourceAccepted(10 * kMsUs, std::nullopt);
  EXPECT_TRUE(check.CheckOther("nominal", 10 * kMsUs, 10 * kMsUs, std::nullopt));
  EXPECT_FALSE(check.CheckOther("nominal", 10 * kMsUs + 1'000'000'000'000,
                                10 * kMsUs + 1'000'000'000'000, std::nullopt));
  EXPECT_EQ(counters.counter("rejected_nominal_time_implausible"), 1);
  EXPECT_EQ(counters.counter("rejected_state_time_implausible"), 0);
  EXPECT_EQ(check.plausibility().newest_utime(), 10 * kMsUs);
  EXPECT_FALSE(check.starved());
}

TEST(InputTimeCheck, RejectingEveryMessageIsALatchedFaultUntilPlausibleInputReturns) {
  HealthCounters counters("controller");
  counters.SetState(health_state::kOk);
  InputTimeCheck check({1.0, 100.0}, "state", 0.02, &counters);
  check.SourceAccepted(60'000 * kMsUs, kWallUs);
  // A stream from 0 again (a new lockstep plant), every message behind.
  for (int64_t k = 0; k < 30; ++k) {
    EXPECT_FALSE(check.CheckSource(k * kMsUs, k * kMsUs, kWallUs + (k + 1) * kMsUs));
  }
  EXPECT_TRUE(check.starved());
  EXPECT_EQ(counters.state(), health_state::kFault);
  EXPECT_TRUE(counters.fault_latched());
  EXPECT_NE(counters.latched_error().find("every state rejected"), std::string::npos)
      << counters.latched_error();
  // Plausible input again: OK now, the fault stays latched for the operator.
  ASSERT_TRUE(check.CheckSource(60'001 * kMsUs, 60'001 * kMsUs, kWallUs + 31 * kMsUs));
  check.SourceAccepted(60'001 * kMsUs, kWallUs + 31 * kMsUs);
  EXPECT_FALSE(check.starved());
  EXPECT_EQ(counters.state(), health_state::kOk);
  EXPECT_TRUE(counters.fault_latched());
}

TEST(InputTimeCheck, CopiesOfTheNewestMessageAreNotStarvation) {
  HealthCounters counters("estimator");
  InputTimeCheck check({1.0, 100.0}, "sensor", 0.05, &counters);
  check.SourceAccepted(5 * kMsUs, kWallUs);
  // Lockstep re-sends an unanswered sample every 200 ms; the process drops
  // the copies by its own time order.
  for (int64_t k = 1; k < 10; ++k) {
    ASSERT_TRUE(check.CheckSource(5 * kMsUs, 5 * kMsUs, kWallUs + k * 200 * kMsUs));
    check.SourceRejected(5 * kMsUs, kWallUs + k * 200 * kMsUs);
  }
  EXPECT_FALSE(check.starved());
  EXPECT_FALSE(counters.fault_latched());
}

}  // namespace
}  // namespace stewart
