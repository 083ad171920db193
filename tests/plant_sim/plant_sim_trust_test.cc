// Only the safety session moves the simulated platform, and plant_sim's own
// guard stops it when nothing else does (docs/operations.md, "Trust model"):
// the real plant_sim process over LCM (private URLs, ports 7900-7907), the
// test standing in for the safety process (FakeSafetySession) and for
// whoever else is on the bus.
//
// The attack found before: a forged CMD_SAFE copying the real command's
// sample_utime with 1e300 N was applied, and took zd to 0.647 m/s and z to
// 0.524 m (limit 0.51). Here the same forgery, every sample, with another
// session id, a replayed seq, or (with a key) no valid MAC, must leave the
// platform where the real commands hold it.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "plant_test_util.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/message_auth.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/fake_safety_session.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;
using test::Config;

int64_t Counter(const health_t& h, const std::string& name) {
  for (int i = 0; i < h.num_counters; ++i) {
    if (h.counter_names[static_cast<std::size_t>(i)] == name) {
      return h.counter_values[static_cast<std::size_t>(i)];
    }
  }
  return -1;
}

/// A key file (mode 600) and an overlay that sets it; removed at the end.
struct KeyFiles {
  KeyFiles() {
    const std::string dir = ::testing::TempDir();
    key = dir + "/plant_sim_trust_" + std::to_string(getpid()) + ".key";
    overlay = dir + "/plant_sim_trust_" + std::to_string(getpid()) + ".yaml";
    std::ofstream(key) << "00112233445566778899aabbccddeeff0123456789abcdef0123456789abcdef\n";
    chmod(key.c_str(), 0600);
    std::ofstream(overlay) << "lcm:\n  auth_key_file: " << key << "\n";
  }
  ~KeyFiles() {
    std::remove(key.c_str());
    std::remove(overlay.c_str());
  }
  std::string key, overlay;
};

/// The bus as plant_sim sees it: the real safety session answering every
/// sample with the holding force (the platform stays put), an optional
/// forger acting on every sample before the real answer goes out, and what
/// plant_sim publishes.
class Bus {
 public:
  using Forger = std::function<void(const sensor_t&, test::FakeSafetySession&)>;

  explicit Bus(const std::string& url, MessageAuthenticator auth = {})
      : lcm_(MakeLcm(url)),
        safety_(lcm_.get(), Config().lcm.channels.supervisor, Config().lcm.channels.command_safe,
                4242, std::move(auth)),
        intruder_(lcm_.get(), Config().lcm.channels.supervisor, Config().lcm.channels.command_safe,
                  999) {
    const auto& ch = Config().lcm.channels;
    lcm_->subscribe(ch.sensors, &Bus::OnSensor, this)->setQueueCapacity(10000);
    lcm_->subscribe(ch.state_truth, &Bus::OnTruth, this)->setQueueCapacity(10000);
    lcm_->subscribe(ch.health, &Bus::OnHealth, this)->setQueueCapacity(100);
    hold_n_ = test::HoldingForce(Config().platform, Config().plant_sim.initial_pose);
  }

  void SpinUntilExit(test::ChildProcess* p, double max_seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(max_seconds);
    while (Clock::now() < end && p->running()) lcm_->handleTimeout(5);
    while (lcm_->handleTimeout(20) > 0) {
    }
  }
  void Spin(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) lcm_->handleTimeout(2);
  }

  /// Publishes `f` on CMD_SAFE for `sample_utime` as someone else would:
  /// the given session and seq, the tag as given (zero: no key).
  void Forge(int64_t sample_utime, int64_t session_id, int64_t seq, double force_n) {
    force_command_t cmd{};
    cmd.utime = cmd.sample_utime = sample_utime;
    cmd.seq = seq;
    cmd.session_id = session_id;
    for (double& f : cmd.force_n) f = force_n;
    lcm_->publish(Config().lcm.channels.command_safe, &cmd);
    ++forged;
  }
  /// A second stack on the bus: its own session, announced, numbered.
  void Intrude(int64_t sample_utime, double force_n) {
    force_command_t cmd{};
    cmd.utime = cmd.sample_utime = sample_utime;
    for (double& f : cmd.force_n) f = force_n;
    intruder_.Publish(cmd);
    ++forged;
  }
  void Answer(int64_t sample_utime, const Vector6d& f) {
    force_command_t cmd{};
    cmd.utime = cmd.sample_utime = sample_utime;
    for (int i = 0; i < 6; ++i) cmd.force_n[i] = f(i);
    safety_.Publish(cmd);
  }
  void SendReset(MessageAuthenticator* auth, int64_t operator_id, int64_t seq) {
    operator_command_t c{};
    c.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
    c.seq = seq;
    c.operator_id = operator_id;
    c.command = operator_command_t::COMMAND_RESET;
    c.note = "test";
    if (auth != nullptr) auth->Sign(&c);
    lcm_->publish(Config().lcm.channels.operator_command, &c);
  }

  /// Worst |zd| and highest z on ground truth (m/s, m), and the most any
  /// leg moved from the start (m).
  double max_abs_zd() const {
    double m = 0.0;
    for (const state_t& s : truth) m = std::max(m, std::abs(s.qd[2]));
    return m;
  }
  double max_z() const {
    double m = -1.0;
    for (const state_t& s : truth) m = std::max(m, s.q[2]);
    return m;
  }
  const health_t& last_health() const { return health.back(); }

  Forger forger;
  bool answer = true;
  Vector6d extra_n = Vector6d::Zero();  // added to the holding force
  std::vector<sensor_t> sensors;
  std::vector<state_t> truth;
  std::vector<health_t> health;
  long forged = 0;
  Vector6d hold_n_;
  test::FakeSafetySession& safety() { return safety_; }

 private:
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* s) {
    if (!sensors.empty() && sensors.back().seq == s->seq) return;  // startup resend
    sensors.push_back(*s);
    if (forger) forger(*s, safety_);
    if (answer) Answer(s->utime, hold_n_ + extra_n);
  }
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* s) {
    truth.push_back(*s);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* h) {
    if (h->name == "plant_sim") health.push_back(*h);
  }

  std::unique_ptr<lcm::LCM> lcm_;
  test::FakeSafetySession safety_;
  test::FakeSafetySession intruder_;
};

std::vector<std::string> PlantSim(const std::string& url, const std::string& mode,
                                  double duration_s, const std::string& overlay = "") {
  std::vector<std::string> args = {
      PLANT_SIM_BIN, "--lcm-url", url, "--mode", mode, "--duration", std::to_string(duration_s),
      "--log-level", "warn"};
  if (!overlay.empty()) {
    args.push_back("--overlay");
    args.push_back(overlay);
  }
  return args;
}

// No key, lockstep: before every real answer, a 1e300 N command copying the
// sample's utime from no session, from another (announced) session, and,
// after it, the real answer's copy with its seq. None is applied, none is
// the lockstep answer, and the platform stays where the holding force keeps
// it.
TEST(PlantSimTrust, LockstepForgeriesWithoutTheSessionOrSeqAreDropped) {
  const std::string url = PrivateLcmUrl(7900);
  Bus bus(url);
  bus.answer = false;  // the forger below answers, between its forgeries
  bus.forger = [&bus](const sensor_t& s, test::FakeSafetySession& real) {
    // The real session is announced first (it was running before the
    // second stack); then, for every sample, before the real answer:
    if (s.seq == 0) real.Announce(s.utime);
    bus.Forge(s.utime, 0, 1'000'000 + s.seq, 1e300);  // no session
    bus.Intrude(s.utime, 1e300);                      // a second stack: its own announced session
    bus.Answer(s.utime, bus.hold_n_);
    // After it: a copy of the real answer (its session and seq), 1e300 N.
    bus.Forge(s.utime, real.session_id(), real.next_seq() - 1, 1e300);
  };
  test::ChildProcess sim(PlantSim(url, "lockstep", 0.5));
  bus.SpinUntilExit(&sim, 20.0);
  EXPECT_EQ(sim.Wait(), 0);
  ASSERT_EQ(bus.truth.size(), 501u);
  ASSERT_FALSE(bus.health.empty());
  const health_t& h = bus.last_health();
  EXPECT_GE(Counter(h, "rejected_command_wrong_session"), 2 * 500);
  // The copy after the last answer (sample 499) races the plant's exit
  // after its last sample: it may come after the final heartbeat.
  EXPECT_GE(Counter(h, "rejected_command_seq_not_increasing"), 499);
  EXPECT_GE(Counter(h, "rejected_supervisor_session_busy"), 5);
  EXPECT_EQ(Counter(h, "guard_trips"), 0);
  EXPECT_EQ(Counter(h, "sessions_adopted"), 1);
  EXPECT_LT(bus.max_abs_zd(), 1e-3);
  EXPECT_LT(bus.max_z(), Config().plant_sim.initial_pose(2) + 1e-3);
  std::printf("[trust] lockstep, no key: %ld forgeries, max |zd| %.2e m/s, max z %.5f m\n",
              bus.forged, bus.max_abs_zd(), bus.max_z());
}

// With a key, real time: the forger knows the session and the next seq (it
// reads the bus) and sends first; without the key its tag cannot verify.
TEST(PlantSimTrust, RealTimeWithAKeyForgeriesWithoutAValidMacAreDropped) {
  const KeyFiles files;
  const std::string url = PrivateLcmUrl(7901);
  Bus bus(url, MessageAuthenticator::FromKeyFile(files.key));
  bus.forger = [&bus](const sensor_t& s, test::FakeSafetySession& real) {
    bus.Forge(s.utime, real.session_id(), real.next_seq(), 1e300);
  };
  test::ChildProcess sim(PlantSim(url, "realtime", 1.5, files.overlay));
  bus.SpinUntilExit(&sim, 20.0);
  EXPECT_EQ(sim.Wait(), 0);
  ASSERT_GT(bus.truth.size(), 1000u);
  const health_t& h = bus.last_health();
  EXPECT_GT(Counter(h, "rejected_command_unauthentic"), 1000);
  EXPECT_EQ(Counter(h, "guard_trips"), 0);
  EXPECT_GT(Counter(h, "commands_trusted"), 1000);  // the real ones still act
  EXPECT_LT(bus.max_abs_zd(), 1e-3);
  EXPECT_LT(bus.max_z(), Config().plant_sim.initial_pose(2) + 1e-3);
  std::printf("[trust] real time, key: %ld forgeries, max |zd| %.2e m/s, max z %.5f m\n",
              bus.forged, bus.max_abs_zd(), bus.max_z());
}

// With a key, a session announced without the key is not adopted: nothing
// the unkeyed sender says moves the platform, and the legs stay held.
TEST(PlantSimTrust, WithAKeyAnUnsignedSessionIsNotFollowed) {
  const KeyFiles files;
  const std::string url = PrivateLcmUrl(7902);
  Bus bus(url);  // no key: its announcements and commands are unsigned
  bus.extra_n = Vector6d::Constant(5.0);
  test::ChildProcess sim(PlantSim(url, "realtime", 0.6, files.overlay));
  bus.SpinUntilExit(&sim, 20.0);
  EXPECT_EQ(sim.Wait(), 0);
  const health_t& h = bus.last_health();
  EXPECT_GT(Counter(h, "rejected_supervisor_unauthentic"), 0);
  EXPECT_GT(Counter(h, "rejected_command_unauthentic"), 300);
  EXPECT_EQ(Counter(h, "sessions_adopted"), 0);
  EXPECT_LT(bus.max_abs_zd(), 1e-3);
  ASSERT_FALSE(bus.sensors.empty());
  EXPECT_TRUE(bus.sensors.back().status & sensor_t::STATUS_ACTUATORS_OFF);
}

// The stale command found before: with the estimator stopped for 0.5 s the
// safety process kept answering with hold commands of the last state it
// had, and plant_sim applied 433 of them, up to 483 ms old. Here the
// stand-in safety does the same: for 0.5 s every answer carries the sample
// it last saw. None older than command_timeout_s is applied: the legs are
// held instead, and plant_sim's heartbeat says so.
TEST(PlantSimTrust, RealTimeCommandsOlderThanTheStaleAgeAreNeverApplied) {
  const std::string url = PrivateLcmUrl(7903);
  Bus bus(url);
  bus.answer = false;
  bool stalled = false;
  int64_t stalled_utime = 0;
  const auto started = Clock::now();
  bus.forger = [&](const sensor_t& s, test::FakeSafetySession&) {
    const double t = std::chrono::duration<double>(Clock::now() - started).count();
    const bool stall = t > 0.5 && t < 1.0;
    if (stall && !stalled) stalled_utime = s.utime;
    stalled = stall;
    bus.Answer(stall ? stalled_utime : s.utime, bus.hold_n_);
  };
  test::ChildProcess sim(PlantSim(url, "realtime", 1.5));
  bus.SpinUntilExit(&sim, 20.0);
  EXPECT_EQ(sim.Wait(), 0);
  const health_t& h = bus.last_health();
  const int64_t max_age_us = std::llround(Config().plant_sim.command_timeout_s * 1e6);
  EXPECT_GT(Counter(h, "rejected_command_stale_sample"), 300);
  EXPECT_LE(Counter(h, "applied_age_max_us"), max_age_us);
  EXPECT_GE(Counter(h, "command_timeouts"), 1);
  // The legs were held meanwhile: some samples say so.
  long off = 0;
  for (const sensor_t& s : bus.sensors) off += (s.status & sensor_t::STATUS_ACTUATORS_OFF) ? 1 : 0;
  EXPECT_GT(off, 300);
  std::printf("[trust] stalled answers: %ld rejected as stale, oldest applied %ld us (limit %ld)\n",
              static_cast<long>(Counter(h, "rejected_command_stale_sample")),
              static_cast<long>(Counter(h, "applied_age_max_us")), static_cast<long>(max_age_us));
}

// The guard on plant_sim's own readings: the real session itself pushes
// too hard (under the force bound); the legs exceed the speed cap, the
// drive goes off and stays off (latched) although the commands continue,
// health says FAULT; an unsigned RESET is refused with a key; a signed one
// clears it once the legs are at rest inside their margins.
TEST(PlantSimTrust, GuardTripsOnSpeedLatchesAndClearsOnAnAuthenticReset) {
  const KeyFiles files;
  MessageAuthenticator auth = MessageAuthenticator::FromKeyFile(files.key);
  const std::string url = PrivateLcmUrl(7904);
  Bus bus(url, MessageAuthenticator::FromKeyFile(files.key));
  test::ChildProcess sim(PlantSim(url, "realtime", 0, files.overlay));
  const auto until = [&](const std::function<bool()>& done, double max_s) {
    const auto end = Clock::now() + std::chrono::duration<double>(max_s);
    while (!done() && Clock::now() < end) bus.Spin(0.01);
    return done();
  };
  // Held for 0.5 s first: the guard's speed window is full when the push
  // starts, as it is in operation once the stack is up.
  ASSERT_TRUE(until([&] { return bus.sensors.size() > 500; }, 5.0));
  bus.extra_n = Vector6d::Constant(10.0);
  const auto tripped = [&] {
    return !bus.health.empty() && Counter(bus.last_health(), "guard_tripped") == 1;
  };
  ASSERT_TRUE(until(tripped, 5.0));
  const health_t trip = bus.last_health();
  EXPECT_EQ(trip.state, static_cast<int8_t>(health_t::STATE_FAULT));
  EXPECT_NE(trip.last_error.find("speed"), std::string::npos) << trip.last_error;
  // Held although the session keeps pushing.
  bus.Spin(0.3);
  ASSERT_FALSE(bus.truth.empty());
  EXPECT_LT(std::abs(bus.truth.back().qd[2]), 1e-3);
  bus.extra_n = Vector6d::Zero();
  bus.SendReset(nullptr, 99, 1);  // no tag: refused
  bus.Spin(0.6);
  EXPECT_EQ(Counter(bus.last_health(), "guard_tripped"), 1);
  EXPECT_GE(Counter(bus.last_health(), "rejected_operator_unauthentic"), 1);
  bus.SendReset(&auth, 99, 2);
  EXPECT_TRUE(until([&] { return Counter(bus.last_health(), "guard_tripped") == 0; }, 3.0));
  EXPECT_EQ(Counter(bus.last_health(), "guard_resets"), 1);
  // A replay of that very RESET is refused (its seq).
  bus.SendReset(&auth, 99, 2);
  bus.Spin(0.6);
  EXPECT_GE(Counter(bus.last_health(), "rejected_operator_seq_not_increasing"), 1);
  // The actuators act again (and the platform was where it was held).
  EXPECT_FALSE(bus.sensors.back().status & sensor_t::STATUS_ACTUATORS_OFF);
  EXPECT_EQ(Counter(bus.last_health(), "guard_trips"), 1);
  std::printf("[trust] guard: %s; max |zd| %.3f m/s\n", trip.last_error.c_str(), bus.max_abs_zd());
  sim.Stop(SIGTERM);
}

}  // namespace
}  // namespace stewart
