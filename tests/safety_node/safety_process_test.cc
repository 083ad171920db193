// The real safety process over LCM: DISARMED until it arms by itself
// (simulation's auto-arm), then a nominal command is filtered and answered
// with the same sample_utime; when nominal commands stop (the controller
// died), each new state is answered with the flagged fallback, and the
// platform stays held when the controller comes back.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/model/dynamics.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/lcm_messages.h"

namespace stewart {
namespace {

constexpr int kPort = 7810;  // this test's private LCM port

state_t MakeState(int64_t utime, const Vector6d& q) {
  state_t s{};
  s.utime = utime;
  s.seq = utime / 1000;
  s.sample_utime = utime;
  ToArray(q, s.q);
  s.status = state_t::STATUS_VALID;
  return s;
}

bool WaitFor(lcm::LCM* lcm, const test::Inbox<force_command_t>& sink, std::size_t count) {
  return test::HandleUntil(
      lcm, [&] { return sink.received.size() >= count; }, 5.0, 50);
}

TEST(SafetyProcess, FiltersNominalAndFallsBackWhenControllerStops) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kPort);
  auto lcm = MakeLcm(url);
  test::Inbox<force_command_t> sink;
  lcm->subscribe(config.lcm.channels.command_safe, &test::Inbox<force_command_t>::On, &sink);
  test::Inbox<supervisor_state_t> supervisor;
  lcm->subscribe(config.lcm.channels.supervisor, &test::Inbox<supervisor_state_t>::On, &supervisor);
  const std::string overlay = ::testing::TempDir() + "safety_process_test_overlay.yaml";
  std::ofstream(overlay)
      << "supervisor:\n  auto_arm: true\n  arming_ramp_s: 0.0\n  fallback_latch_s: 0.0\n";
  test::ChildProcess process(
      {SAFETY_PATH, "--lcm-url", url, "--overlay", overlay, "--log-level", "warn"});
  EXPECT_TRUE(process.started());
  // Give the process time to subscribe: resend the first state until the
  // first answer (the fallback: no nominal command has arrived yet).
  int64_t utime = 1'000'000;
  const Vector6d q = config.home_pose;
  for (int attempt = 0; attempt < 50 && sink.received.empty(); ++attempt) {
    const state_t s = MakeState(utime, q);
    lcm->publish(config.lcm.channels.state_estimate, &s);
    lcm->handleTimeout(100);
    utime += 1000;
  }
  ASSERT_FALSE(sink.received.empty()) << "safety process never answered";
  // Answers to the resent states still on their way, and announcements.
  test::HandleUntil(
      lcm.get(), [] { return false; }, 0.3, 10);
  // Power-on is DISARMED: the drive is off until the first filtered step.
  EXPECT_TRUE(sink.received.back().flags & force_command_t::FLAG_DRIVE_OFF);
  EXPECT_EQ(FromArray(sink.received.back().force_n), Vector6d::Zero());

  // Controller alive: state then nominal (the gravity-holding force at rest
  // violates nothing), answered unchanged with the same sample_utime.
  const Vector6d f_hold =
      InverseDynamics(EvaluateDynamics(config.platform, q, Vector6d::Zero()), Vector6d::Zero());
  // The first pair only shows the controller is alive: its state came before
  // any nominal command existed, so it was answered by the fallback already.
  // Every other pair arrives reordered, nominal first (multicast from two
  // senders is not ordered): it must wait for its state, not be dropped.
  for (int k = 0; k < 11; ++k) {
    utime += 1000;
    const state_t s = MakeState(utime, q);
    force_command_t nominal{};
    nominal.utime = nominal.sample_utime = utime;
    nominal.seq = k;
    ToArray(f_hold, nominal.force_n);
    if (k % 2 == 0) {
      lcm->publish(config.lcm.channels.state_estimate, &s);
      lcm->publish(config.lcm.channels.command_nominal, &nominal);
    } else {
      lcm->publish(config.lcm.channels.command_nominal, &nominal);
      lcm->publish(config.lcm.channels.state_estimate, &s);
    }
    const std::size_t before = sink.received.size();
    if (k == 0) {
      WaitFor(lcm.get(), sink, before + 1);  // the fallback's answer to this state
      continue;
    }
    ASSERT_TRUE(WaitFor(lcm.get(), sink, before + 1));
    const force_command_t& safe = sink.received.back();
    EXPECT_EQ(safe.sample_utime, utime);
    EXPECT_EQ(safe.flags & (force_command_t::FLAG_FALLBACK | force_command_t::FLAG_DRIVE_OFF), 0);
    EXPECT_NEAR((FromArray(safe.force_n) - f_hold).norm(), 0.0, 1e-9);
  }
  // The session: announced before the commands, carried by each of them.
  ASSERT_FALSE(supervisor.received.empty());
  const int64_t session = supervisor.received.front().session_id;
  EXPECT_NE(session, 0);
  EXPECT_EQ(supervisor.received.back().state, int8_t{supervisor_state_t::STATE_ARMED});
  for (const force_command_t& c : sink.received) EXPECT_EQ(c.session_id, session);

  // Controller killed: states keep coming, nominal commands stop. Within
  // stale_age_s of state time every state is answered by the fallback.
  const int64_t last_nominal = utime;
  const int64_t stale_us = static_cast<int64_t>(config.safety.stale_age_s * 1e6);
  bool fallback_seen = false;
  for (int k = 0; k < 100 && !fallback_seen; ++k) {
    utime += 1000;
    const state_t s = MakeState(utime, q);
    const std::size_t before = sink.received.size();
    lcm->publish(config.lcm.channels.state_estimate, &s);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
    while (sink.received.size() == before && std::chrono::steady_clock::now() < deadline) {
      lcm->handleTimeout(10);
    }
    if (sink.received.size() > before) {
      const force_command_t& cmd = sink.received.back();
      ASSERT_TRUE(cmd.flags & force_command_t::FLAG_FALLBACK) << "non-fallback without nominal";
      EXPECT_TRUE(cmd.flags & force_command_t::FLAG_STALE_INPUT);
      EXPECT_EQ(cmd.sample_utime, utime);
      EXPECT_TRUE(FromArray(cmd.force_n).allFinite());
      fallback_seen = true;
    }
  }
  ASSERT_TRUE(fallback_seen);
  EXPECT_LE(utime - last_nominal, stale_us + 1000) << "fallback later than the configured age";

  // The controller is back: the supervisor latched HOLD, so the answers stay
  // the safe stop until an operator resumes.
  for (int k = 0; k < 20; ++k) {
    utime += 1000;
    const state_t s = MakeState(utime, q);
    force_command_t nominal{};
    nominal.utime = nominal.sample_utime = utime;
    nominal.seq = 100 + k;
    ToArray(f_hold, nominal.force_n);
    const std::size_t before = sink.received.size();
    lcm->publish(config.lcm.channels.state_estimate, &s);
    lcm->publish(config.lcm.channels.command_nominal, &nominal);
    ASSERT_TRUE(WaitFor(lcm.get(), sink, before + 1));
    EXPECT_TRUE(sink.received.back().flags & force_command_t::FLAG_FALLBACK) << k;
  }
  test::HandleUntil(
      lcm.get(), [&] { return supervisor.received.back().state == supervisor_state_t::STATE_HOLD; },
      1.0);
  EXPECT_EQ(supervisor.received.back().state, int8_t{supervisor_state_t::STATE_HOLD});
  EXPECT_EQ(supervisor.received.back().fault_latched, 1);
}

}  // namespace
}  // namespace stewart
