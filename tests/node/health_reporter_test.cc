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

TEST(HealthReporter, CountsSinceStartAndSinceThePreviousHeartbeat) {
  HealthReporter health("safety", "TEST_HEALTH", 2.0);
  health.SetResetSource([] { return OperatorResetCounts{}; });
  health.CountIn();
  health.CountIn();
  health.CountOut();
  health.Reject("state_time_implausible");
  health.Count("fallback_commands", 3);
  const health_t first = health.Snapshot();
  EXPECT_EQ(first.period_us, 0);
  EXPECT_EQ(first.messages_in, 2);
  EXPECT_EQ(first.messages_in_delta, 2);
  EXPECT_EQ(first.rejected_inputs_delta, 1);
  ASSERT_EQ(first.num_counters, 2);
  EXPECT_EQ(first.counter_deltas[0], 1);  // rejected_state_time_implausible
  EXPECT_EQ(first.counter_deltas[1], 3);  // fallback_commands

  health.CountIn();
  health.Count("fallback_commands");
  health.Count("infeasible");  // new since the previous heartbeat
  const health_t second = health.Snapshot();
  EXPECT_GT(second.period_us, 0);
  EXPECT_EQ(second.messages_in, 3);
  EXPECT_EQ(second.messages_in_delta, 1);
  EXPECT_EQ(second.messages_out_delta, 0);
  EXPECT_EQ(second.rejected_inputs, 1);
  EXPECT_EQ(second.rejected_inputs_delta, 0);
  ASSERT_EQ(second.num_counters, 3);
  ASSERT_EQ(second.counter_deltas.size(), 3u);
  EXPECT_EQ(second.counter_values[1], 4);
  EXPECT_EQ(second.counter_deltas[0], 0);
  EXPECT_EQ(second.counter_deltas[1], 1);
  EXPECT_EQ(second.counter_deltas[2], 1);
}

TEST(HealthReporter, AStateBetweenTwoHeartbeatsShowsInTheNext) {
  HealthReporter health("controller", "TEST_HEALTH", 2.0);
  health.SetResetSource([] { return OperatorResetCounts{}; });
  health.SetState(health_t::STATE_OK);
  health.Snapshot();
  health.SetState(health_t::STATE_DEGRADED);  // 0.47 s, between two heartbeats
  health.SetState(health_t::STATE_OK);
  const health_t beat = health.Snapshot();
  EXPECT_EQ(beat.state, +health_t::STATE_OK);
  EXPECT_EQ(beat.worst_state, +health_t::STATE_DEGRADED);
  EXPECT_FALSE(beat.fault_latched);
  const health_t next = health.Snapshot();
  EXPECT_EQ(next.worst_state, +health_t::STATE_OK);
}

TEST(HealthReporter, AFaultStaysLatchedUntilAnOperatorReset) {
  OperatorResetCounts resets;
  HealthReporter health("estimator", "TEST_HEALTH", 2.0);
  health.SetResetSource([&resets] { return resets; });
  health.SetError("every sensor rejected");
  health.SetState(health_t::STATE_FAULT);
  health.SetState(health_t::STATE_OK);
  health_t beat = health.Snapshot();
  EXPECT_EQ(beat.worst_state, +health_t::STATE_FAULT);
  EXPECT_TRUE(beat.fault_latched);
  EXPECT_EQ(beat.latched_error, "every sensor rejected");
  beat = health.Snapshot();  // still latched, however many heartbeats later
  EXPECT_EQ(beat.worst_state, +health_t::STATE_OK);
  EXPECT_TRUE(beat.fault_latched);
  resets.rejected_auth = 1;  // a RESET that did not verify acknowledges nothing
  beat = health.Snapshot();
  EXPECT_TRUE(beat.fault_latched);
  resets.accepted = 1;
  beat = health.Snapshot();
  EXPECT_FALSE(beat.fault_latched);
  EXPECT_EQ(beat.latched_error, "");
  // A fault that persists through the RESET stays latched.
  health.SetState(health_t::STATE_FAULT);
  resets.accepted = 2;
  beat = health.Snapshot();
  EXPECT_TRUE(beat.fault_latched);
  EXPECT_EQ(beat.state, +health_t::STATE_FAULT);
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
