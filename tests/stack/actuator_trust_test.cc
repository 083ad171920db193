// The actuators' trust rules with the real stack (plant_sim in real time,
// estimator, controller, safety with its supervisor; armed automatically as
// in simulation), on private URLs (LCM ports 7914-7917; docs/operations.md,
// "Trust model"):
//
// - the estimator stopped (SIGSTOP) for 0.5 s: before, plant_sim applied 433
//   commands older than 50 ms, up to 483 ms; now none older than
//   plant_sim.command_timeout_s, counted from plant_sim's own heartbeat;
// - the attack found before: a forged STEWART_CMD_SAFE copying every real
//   command's sample_utime with 1e300 N (it took zd to 0.647 m/s and z to
//   0.524 m, limit 0.51): without a key from no session and as the real
//   command's copy (its session and seq), with a key as the real session's
//   next seq without a valid MAC. plant_sim drops every one; the platform
//   keeps its limits on ground truth. Without a key, a copy of a real
//   command that plant_sim lost is indistinguishable from it: then its guard
//   trips on the copy's force (the only trip accepted), and the estimator,
//   which may lose one too, takes such a force as the drive off.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

int64_t Counter(const health_t& h, const std::string& name) {
  for (int i = 0; i < h.num_counters; ++i) {
    if (h.counter_names[static_cast<std::size_t>(i)] == name) {
      return h.counter_values[static_cast<std::size_t>(i)];
    }
  }
  return -1;
}

/// How the forger acts on each real safe command it sees.
enum class Forgery { kNone, kNoSession, kCopyOfTheReal, kNextSeqWithoutMac };

/// The bus as a bystander sees it, and the forger.
class Bus {
 public:
  Bus(const StackConfig& config, const std::string& url) : config_(config), lcm_(MakeLcm(url)) {
    const auto& ch = config.lcm.channels;
    lcm_->subscribe(ch.command_safe, &Bus::OnSafe, this)->setQueueCapacity(100000);
    lcm_->subscribe(ch.state_truth, &Bus::OnTruth, this)->setQueueCapacity(100000);
    lcm_->subscribe(ch.health, &Bus::OnHealth, this)->setQueueCapacity(1000);
  }
  void Spin(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) lcm_->handleTimeout(5);
  }

  Forgery forgery = Forgery::kNone;
  long forged = 0;
  long real_commands = 0;
  std::vector<state_t> truth;
  health_t plant{};
  bool have_plant = false;
  std::vector<health_t> estimator;

 private:
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
    if (msg->force_n[0] == 1e300) return;  // our own
    ++real_commands;
    if (forgery == Forgery::kNone) return;
    force_command_t f = *msg;
    for (double& x : f.force_n) x = 1e300;
    f.flags = 0;
    switch (forgery) {
      case Forgery::kNoSession:
        f.session_id = 0;
        break;
      case Forgery::kCopyOfTheReal:  // its session, its seq: a replay
        break;
      case Forgery::kNextSeqWithoutMac:  // what a reader of the bus can guess
        f.seq += 1;
        for (auto& b : f.mac) b = 0;
        break;
      case Forgery::kNone:
        return;
    }
    lcm_->publish(config_.lcm.channels.command_safe, &f);
    ++forged;
  }
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
    truth.push_back(*msg);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    if (msg->name == "plant_sim") plant = *msg, have_plant = true;
    if (msg->name == "estimator") estimator.push_back(*msg);
  }

  StackConfig config_;
  std::unique_ptr<lcm::LCM> lcm_;
};

/// The four processes on `url`, armed automatically, with a key or not.
struct Stack {
  Stack(const std::string& url, bool with_key) {
    const std::string stem = ::testing::TempDir() + "/actuator_trust_" + std::to_string(getpid());
    overlay = stem + (with_key ? "_key.yaml" : ".yaml");
    key = stem + ".key";
    std::ofstream out(overlay);
    out << "supervisor:\n  auto_arm: true\n";
    if (with_key) {
      std::ofstream(key) << "0badc0ffee0ddf00d5eed5eed0123456789abcdef0123456789abcdef0123456\n";
      ::chmod(key.c_str(), 0600);
      out << "lcm:\n  auth_key_file: \"" << key << "\"\n";
    }
    out.close();
    // Errors only: a failure's own lines must stay near the top of the
    // test's output (a loaded machine logs every late tick as a warning).
    const std::vector<std::string> common = {"--lcm-url", url,           "--overlay",
                                             overlay,     "--log-level", "error"};
    auto with = [&](std::vector<std::string> head) {
      head.insert(head.end(), common.begin(), common.end());
      return head;
    };
    safety = std::make_unique<test::ChildProcess>(with({SAFETY_PATH}));
    controller =
        std::make_unique<test::ChildProcess>(with({CONTROLLER_PATH, "--scenario", "paper"}));
    estimator = std::make_unique<test::ChildProcess>(with({ESTIMATOR_PATH}));
    plant = std::make_unique<test::ChildProcess>(with({PLANT_SIM_PATH, "--mode", "realtime"}));
  }
  ~Stack() {
    plant.reset();
    estimator.reset();
    controller.reset();
    safety.reset();
    std::remove(overlay.c_str());
    std::remove(key.c_str());
  }
  bool started() const {
    return safety->started() && controller->started() && estimator->started() && plant->started();
  }
  std::string overlay, key;
  std::unique_ptr<test::ChildProcess> safety, controller, estimator, plant;
};

/// Ground truth within the z and zd limits (1 mm, 1 mm/s tolerance).
void ExpectZLimitsHeld(const Bus& bus, const StackConfig& config) {
  double max_z = -1.0, max_zd = -1.0;
  for (const state_t& s : bus.truth) {
    max_z = std::max(max_z, s.q[2]);
    max_zd = std::max(max_zd, s.qd[2]);
  }
  EXPECT_LT(max_z, 0.51 + 1e-3);
  EXPECT_LT(max_zd, 0.010 + 1e-3);
  std::printf("[trust] max z %.4f m, max zd %.4f m/s over %zu truth samples\n", max_z, max_zd,
              bus.truth.size());
  (void)config;
}

TEST(ActuatorTrust, EstimatorStoppedHalfASecondNoStaleCommandIsApplied) {
  test::LauncherLock lock;  // a real-time stack: no other stack or browser beside it
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(7914);
  Bus bus(config, url);
  Stack stack(url, false);
  ASSERT_TRUE(stack.started());
  bus.Spin(3.0);  // up, armed, moving
  ASSERT_GT(bus.real_commands, 1000) << "the stack did not come up";
  stack.estimator->Signal(SIGSTOP);
  bus.Spin(0.5);
  stack.estimator->Signal(SIGCONT);
  bus.Spin(2.0);  // and a heartbeat after it
  ASSERT_TRUE(bus.have_plant);
  const int64_t limit_us = std::llround(config.plant_sim.command_timeout_s * 1e6);
  const int64_t oldest = Counter(bus.plant, "applied_age_max_us");
  EXPECT_GE(oldest, 0);
  EXPECT_LE(oldest, limit_us);
  EXPECT_EQ(Counter(bus.plant, "guard_trips"), 0);
  std::printf(
      "[trust] estimator stopped 0.5 s: oldest command applied %lld us (limit %lld), %lld "
      "rejected as stale, %lld command timeouts\n",
      static_cast<long long>(oldest), static_cast<long long>(limit_us),
      static_cast<long long>(Counter(bus.plant, "rejected_command_stale_sample")),
      static_cast<long long>(Counter(bus.plant, "command_timeouts")));
  ExpectZLimitsHeld(bus, config);
}

struct AttackCase {
  Forgery forgery;
  bool with_key;
  int port;
  const char* counter;  // plant_sim's rejection counter for the forgeries
};

class ActuatorTrustAttack : public ::testing::TestWithParam<AttackCase> {};

TEST_P(ActuatorTrustAttack, ForgedCommandsAreDroppedAndTheLimitsHold) {
  test::LauncherLock lock;  // a real-time stack: no other stack or browser beside it
  const AttackCase& c = GetParam();
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(c.port);
  Bus bus(config, url);
  Stack stack(url, c.with_key);
  ASSERT_TRUE(stack.started());
  bus.Spin(2.0);
  ASSERT_GT(bus.real_commands, 1000) << "the stack did not come up";
  bus.forgery = c.forgery;
  bus.Spin(3.0);
  bus.forgery = Forgery::kNone;
  bus.Spin(0.7);  // a heartbeat after the last forgery
  ASSERT_TRUE(bus.have_plant);
  EXPECT_GT(bus.forged, 1000);
  // Every forgery dropped, for the reason expected (a few may be still in
  // flight when the heartbeat was taken).
  EXPECT_GE(Counter(bus.plant, c.counter), bus.forged - 50) << c.counter;
  // It trusted the real commands, no more (fewer by those after its last
  // heartbeat, <= 0.5 s, and before it had a session).
  EXPECT_LE(Counter(bus.plant, "commands_trusted"), bus.real_commands);
  EXPECT_GE(Counter(bus.plant, "commands_trusted"), bus.real_commands - 700);
  EXPECT_EQ(Counter(bus.plant, "sessions_adopted"), 1);
  // The estimator believes only what the plant applies: it counts the same
  // forgeries, its estimate stays right, and the filter never commands
  // beyond guard.leg_force_limit_n (before, believing every CMD_SAFE, it did:
  // leg 0 at -21.3 N, and plant_sim's guard had to hold the platform).
  ASSERT_FALSE(bus.estimator.empty());
  EXPECT_GE(Counter(bus.estimator.back(), c.counter), bus.forged - 50) << c.counter;
  const int64_t trips = Counter(bus.plant, "guard_trips");
  if (c.forgery == Forgery::kCopyOfTheReal && trips == 1) {
    // Without a key a copy is the real command to whoever lost the real one
    // (a full socket buffer on a loaded machine): plant_sim then trusts it,
    // and its guard must turn the drive off on the 1e300 N it carries.
    EXPECT_NE(bus.plant.last_error.find("commanded force 1e+300 N beyond the bound"),
              std::string::npos)
        << bus.plant.last_error;
    std::printf("[trust] plant_sim lost a real command and trusted its copy: %s\n",
                bus.plant.last_error.c_str());
  } else {
    EXPECT_EQ(trips, 0) << bus.plant.last_error;
  }
  std::printf("[trust] plant_sim: %s; estimator: %s\n", bus.plant.last_error.c_str(),
              bus.estimator.empty() ? "-" : bus.estimator.back().last_error.c_str());
  std::printf(
      "[trust] %s%s: %ld forgeries, %lld dropped as %s, guard trips %lld; the estimator took "
      "%lld as drive off (beyond the guard's force bound)\n",
      c.with_key ? "key, " : "no key, ", c.counter, bus.forged,
      static_cast<long long>(Counter(bus.plant, c.counter)), c.counter,
      static_cast<long long>(Counter(bus.plant, "guard_trips")),
      static_cast<long long>(std::max<int64_t>(
          0, Counter(bus.estimator.back(), "rejected_command_beyond_guard_force"))));
  ExpectZLimitsHeld(bus, config);
}

INSTANTIATE_TEST_SUITE_P(Forgeries, ActuatorTrustAttack,
                         ::testing::Values(AttackCase{Forgery::kNoSession, false, 7915,
                                                      "rejected_command_wrong_session"},
                                           AttackCase{Forgery::kCopyOfTheReal, false, 7916,
                                                      "rejected_command_seq_not_increasing"},
                                           AttackCase{Forgery::kNextSeqWithoutMac, true, 7917,
                                                      "rejected_command_unauthentic"}));

}  // namespace
}  // namespace stewart
