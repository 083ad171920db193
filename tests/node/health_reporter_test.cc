#include "stewart/node/health_reporter.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "stewart/node/lcm_handle.h"
#include "stewart/test_support/lcm_messages.h"

namespace stewart {
namespace {

constexpr int kPort = 7800;  // this test's private LCM port

TEST(HealthReporter, CountsRejectionsAndPublishes) {
  auto lcm = MakeLcm(PrivateLcmUrl(kPort));
  test::Inbox<health_t> sink;
  lcm->subscribe("TEST_HEALTH", &test::Inbox<health_t>::On, &sink);

  HealthReporter health("estimator", "TEST_HEALTH", 1000.0);
  health.CountIn();
  health.CountIn();
  health.CountOut();
  health.Reject("nan", "leg 2");
  health.Reject("nan");
  health.Reject("stale");
  health.Count("gated", 4);
  health.SetState(health_t::STATE_DEGRADED);
  health.SetStackTime(5000, 4000);
  EXPECT_EQ(health.rejected_inputs(), 3);
  EXPECT_EQ(health.counter("rejected_nan"), 2);
  EXPECT_EQ(health.counter("gated"), 4);

  ASSERT_TRUE(health.MaybePublish(lcm.get(), /*force=*/true));
  EXPECT_FALSE(health.MaybePublish(lcm.get()));  // period not elapsed
  test::HandleUntil(
      lcm.get(), [&] { return !sink.received.empty(); }, 3.0, 100);
  ASSERT_EQ(sink.received.size(), 1u);
  const health_t& last = sink.received.back();
  EXPECT_EQ(last.name, "estimator");
  EXPECT_EQ(last.utime, 5000);
  EXPECT_EQ(last.sample_utime, 4000);
  EXPECT_EQ(last.messages_in, 2);
  EXPECT_EQ(last.messages_out, 1);
  EXPECT_EQ(last.rejected_inputs, 3);
  EXPECT_EQ(last.state, +health_t::STATE_DEGRADED);  // + : lcm-gen constants have no definition
  EXPECT_EQ(last.last_error, "stale");
  ASSERT_EQ(last.num_counters, 3);
  EXPECT_EQ(last.counter_names[0], "rejected_nan");
  EXPECT_EQ(last.counter_values[0], 2);
}

TEST(LcmHandle, BadUrlGivesClearError) {
  try {
    MakeLcm("nosuchprovider://nowhere");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://nowhere"), std::string::npos);
  }
}

}  // namespace
}  // namespace stewart
