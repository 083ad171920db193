// Health that tells the truth, with the real controller process: rejecting
// every state estimate for longer than its stale age is a FAULT in its
// heartbeat; when plausible states return it is OK again but the FAULT
// stays latched, through a RESET that does not verify, until an operator's
// signed RESET acknowledges it. LCM port 7921 (this folder owns 7920-7939).
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/message_auth.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/lcm_messages.h"

namespace stewart {
namespace {

constexpr int kPort = 7921;

int64_t WallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Heartbeats {
  void On(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    if (msg->name == "controller") received.push_back(*msg);
  }
  std::vector<health_t> received;
};

class HealthAck : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = "/tmp/stewart_health_ack_XXXXXX";
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    folder_ = pattern;
    for (size_t i = 0; i < key_.size(); ++i) key_[i] = static_cast<uint8_t>(17 * i + 3);
    const std::string key_path = folder_ + "/auth.key";
    {
      std::ofstream key(key_path);
      for (uint8_t b : key_) {
        char hex[3];
        std::snprintf(hex, sizeof hex, "%02x", b);
        key << hex;
      }
      key << '\n';
    }
    ASSERT_EQ(chmod(key_path.c_str(), 0600), 0);
    overlay_ = folder_ + "/overlay.yaml";
    std::ofstream(overlay_) << "lcm:\n  auth_key_file: " << key_path
                            << "\nrates:\n  health_hz: 20.0\n";
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
  }

  std::string folder_;
  std::string overlay_;
  std::vector<uint8_t> key_ = std::vector<uint8_t>(32);
};

TEST_F(HealthAck, RejectingEveryStateLatchesAFaultUntilASignedReset) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kPort);
  auto lcm = MakeLcm(url);
  Heartbeats beats;
  lcm->subscribe(config.lcm.channels.health, &Heartbeats::On, &beats)->setQueueCapacity(10000);
  test::ChildProcess controller(
      {CONTROLLER_PATH, "--lcm-url", url, "--overlay", overlay_, "--log-level", "warn"});
  ASSERT_TRUE(controller.started());
  ASSERT_TRUE(test::HandleUntil(
      lcm.get(), [&] { return !beats.received.empty(); }, 15.0))
      << "no heartbeat from the controller";

  // States of a lockstep run (stack time from 1 s), one per ms.
  int64_t seq = 0;
  const auto publish_state = [&](int64_t utime) {
    state_t s{};
    s.utime = s.sample_utime = utime;
    s.seq = seq++;
    for (int i = 0; i < 6; ++i) s.q[i] = config.home_pose(i);
    s.status = state_t::STATUS_VALID;
    lcm->publish(config.lcm.channels.state_estimate, &s);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  const auto wait_for_beat = [&](auto condition, const char* what) {
    const size_t from = beats.received.size();
    const bool seen = test::HandleUntil(
        lcm.get(),
        [&] {
          for (size_t i = from; i < beats.received.size(); ++i) {
            if (condition(beats.received[i])) return true;
          }
          return false;
        },
        5.0);
    EXPECT_TRUE(seen) << "no heartbeat " << what << "; last: state "
                      << int{beats.received.back().state} << ", latched "
                      << beats.received.back().fault_latched << " ("
                      << beats.received.back().latched_error << ")";
    return seen;
  };
  for (int64_t k = 0; k < 100; ++k) publish_state(1'000'000 + 1000 * k);
  ASSERT_TRUE(
      wait_for_beat([](const health_t& h) { return h.messages_in >= 100 && !h.fault_latched; },
                    "with the first states taken"));

  // A stream from 0 again, 1.1 s behind what was accepted: every state is
  // rejected, for longer than controller.stale_age_s.
  for (int64_t k = 0; k < 60; ++k) publish_state(1000 * k);
  ASSERT_TRUE(wait_for_beat(
      [](const health_t& h) {
        return h.fault_latched && h.worst_state == health_t::STATE_FAULT &&
               test::HealthCounter(h, "rejected_state_time_implausible") >= 50;
      },
      "with a latched FAULT and the implausible states counted"));

  // Plausible states again: OK now, still latched.
  for (int64_t k = 100; k < 130; ++k) publish_state(1'000'000 + 1000 * k);
  ASSERT_TRUE(wait_for_beat(
      [](const health_t& h) { return h.state != health_t::STATE_FAULT && h.fault_latched; },
      "back from FAULT with the fault still latched"));

  // A RESET under another key acknowledges nothing.
  operator_command_t reset{};
  reset.operator_id = 7;
  reset.seq = 1;
  reset.command = operator_command_t::COMMAND_RESET;
  reset.note = "health_ack_test";
  reset.utime = WallUtime();
  std::vector<uint8_t> other_key = key_;
  other_key[0] ^= 1;
  MessageAuthenticator(other_key).Sign(&reset);
  lcm->publish(config.lcm.channels.operator_command, &reset);
  ASSERT_TRUE(wait_for_beat(
      [](const health_t& h) { return test::HealthCounter(h, "operator_resets_rejected") == 1; },
      "counting the unverified RESET"));
  EXPECT_TRUE(beats.received.back().fault_latched);

  // The operator's RESET: acknowledged at the next heartbeat.
  reset.seq = 2;
  reset.utime = WallUtime();
  MessageAuthenticator(key_).Sign(&reset);
  lcm->publish(config.lcm.channels.operator_command, &reset);
  ASSERT_TRUE(wait_for_beat(
      [](const health_t& h) {
        return !h.fault_latched && test::HealthCounter(h, "operator_resets") == 1;
      },
      "with the fault acknowledged"));
  EXPECT_EQ(beats.received.back().latched_error, "");
  EXPECT_TRUE(controller.running());
}

}  // namespace
}  // namespace stewart
