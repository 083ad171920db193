#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_handle.h"

namespace stewart {
namespace {

constexpr int kPort = 7800;  // this test's private LCM port

class HealthSink {
 public:
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    last = *msg;
    ++received;
  }
  health_t last;
  int received = 0;
};

TEST(HealthReporter, CountsRejectionsAndPublishes) {
  auto lcm = MakeLcm(PrivateLcmUrl(kPort));
  HealthSink sink;
  lcm->subscribe("TEST_HEALTH", &HealthSink::OnHealth, &sink);

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
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (sink.received == 0 && std::chrono::steady_clock::now() < deadline) {
    lcm->handleTimeout(100);
  }
  ASSERT_EQ(sink.received, 1);
  EXPECT_EQ(sink.last.name, "estimator");
  EXPECT_EQ(sink.last.utime, 5000);
  EXPECT_EQ(sink.last.sample_utime, 4000);
  EXPECT_EQ(sink.last.messages_in, 2);
  EXPECT_EQ(sink.last.messages_out, 1);
  EXPECT_EQ(sink.last.rejected_inputs, 3);
  EXPECT_EQ(sink.last.state, +health_t::STATE_DEGRADED);  // + : lcm-gen constants have no definition
  EXPECT_EQ(sink.last.last_error, "stale");
  ASSERT_EQ(sink.last.num_counters, 3);
  EXPECT_EQ(sink.last.counter_names[0], "rejected_nan");
  EXPECT_EQ(sink.last.counter_values[0], 2);
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
