// Only the safety session moves the device, and hw_bridge's own guard stops
// it when nothing else does (docs/operations.md, "Trust model"): hw_emulator
// (the device, its ground truth on LCM) and hw_bridge as processes, the test
// standing in for the safety process (FakeSafetySession) and for whoever
// else is on the bus. LCM ports 7908-7912, device UDP ports 17900-17909.
//
// The attack found before: on this path one forged 100 N CMD_SAFE gave zd
// 0.585 m/s, and twenty drove the platform away. Here one and then twenty,
// from another session, as a replay of the real command's seq, and (with a
// key) with the real session and the next seq but no valid MAC, must leave
// the platform where the holding force keeps it.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/model/dynamics.h"
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
    const std::string stem = ::testing::TempDir() + "/hw_trust_" + std::to_string(getpid());
    key = stem + ".key";
    overlay = stem + ".yaml";
    std::ofstream(key) << "ffeeddccbbaa99887766554433221100fedcba9876543210fedcba9876543210\n";
    chmod(key.c_str(), 0600);
    std::ofstream(overlay) << "lcm:\n  auth_key_file: " << key << "\n";
  }
  ~KeyFiles() {
    std::remove(key.c_str());
    std::remove(overlay.c_str());
  }
  std::string key, overlay;
};

/// hw_emulator and hw_bridge on `lcm_port` and device ports
/// `device_port`, +1; the bridge with `overlay` when given.
struct Device {
  Device(int lcm_port, int device_port, const std::string& overlay = "")
      : url(PrivateLcmUrl(lcm_port)),
        emulator({HW_EMULATOR_EXE, "--transport", "udp", "--device-port",
                  std::to_string(device_port), "--host-port", std::to_string(device_port + 1),
                  "--lcm-url", url, "--log-level", "warn"}),
        bridge(BridgeArgs(url, device_port, overlay)) {}
  static std::vector<std::string> BridgeArgs(const std::string& url, int device_port,
                                             const std::string& overlay) {
    std::vector<std::string> a = {HW_BRIDGE_EXE,
                                  "--lcm-url",
                                  url,
                                  "--device-port",
                                  std::to_string(device_port),
                                  "--local-port",
                                  std::to_string(device_port + 1),
                                  "--log-level",
                                  "warn"};
    if (!overlay.empty()) {
      a.push_back("--overlay");
      a.push_back(overlay);
    }
    return a;
  }
  std::string url;
  test::ChildProcess emulator;
  test::ChildProcess bridge;
};

/// The bus as hw_bridge sees it: the real session answering every sample
/// with the holding force at home, a forger acting before the real answer
/// when armed, the emulator's ground truth and the bridge's heartbeat.
class Bus {
 public:
  using Forger = std::function<void(const sensor_t&, test::FakeSafetySession&)>;

  Bus(const std::string& url, MessageAuthenticator auth = {})
      : config_(LoadStackConfig(DefaultConfigPath())),
        lcm_(MakeLcm(url)),
        safety_(lcm_.get(), config_.lcm.channels.supervisor, config_.lcm.channels.command_safe,
                4242, std::move(auth)) {
    const auto& ch = config_.lcm.channels;
    lcm_->subscribe(ch.sensors, &Bus::OnSensor, this)->setQueueCapacity(10000);
    lcm_->subscribe(ch.state_truth, &Bus::OnTruth, this)->setQueueCapacity(10000);
    lcm_->subscribe(ch.health, &Bus::OnHealth, this)->setQueueCapacity(100);
    const DynamicsTerms home =
        EvaluateDynamics(config_.platform, config_.home_pose, Vector6d::Zero());
    hold_n_ = InverseDynamics(home, Vector6d::Zero());
  }

  void Spin(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) lcm_->handleTimeout(2);
  }
  /// Spins until `n` more sensor samples arrived (at most `max_s`).
  void SpinSamples(std::size_t n, double max_s) {
    const std::size_t target = sensors.size() + n;
    const auto end = Clock::now() + std::chrono::duration<double>(max_s);
    while (sensors.size() < target && Clock::now() < end) lcm_->handleTimeout(2);
  }
  void Forge(int64_t sample_utime, int64_t session_id, int64_t seq, double force_n) {
    force_command_t cmd{};
    cmd.utime = cmd.sample_utime = sample_utime;
    cmd.seq = seq;
    cmd.session_id = session_id;
    for (double& f : cmd.force_n) f = force_n;
    lcm_->publish(config_.lcm.channels.command_safe, &cmd);
    ++forged;
  }
  void SendReset(MessageAuthenticator* auth, int64_t operator_id, int64_t seq) {
    operator_command_t c{};
    c.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
    c.seq = seq;
    c.operator_id = operator_id;
    c.command = operator_command_t::COMMAND_RESET;
    if (auth != nullptr) auth->Sign(&c);
    lcm_->publish(config_.lcm.channels.operator_command, &c);
  }
  /// Worst |zd| and |xd| on ground truth from truth sample `from` on.
  double max_abs_qd(int axis, std::size_t from = 0) const {
    double m = 0.0;
    for (std::size_t k = from; k < truth.size(); ++k) m = std::max(m, std::abs(truth[k].qd[axis]));
    return m;
  }
  bool have_health() const { return !health.empty(); }
  const health_t& last_health() const { return health.back(); }

  Forger forger;  // called per sample before the real answer, then cleared if one_shot
  int forgeries_left = 0;
  Vector6d extra_n = Vector6d::Zero();
  std::vector<sensor_t> sensors;
  std::vector<state_t> truth;
  std::vector<health_t> health;
  long forged = 0;
  Vector6d hold_n_;

 private:
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* s) {
    sensors.push_back(*s);
    if (forger && forgeries_left > 0) {
      forger(*s, safety_);
      --forgeries_left;
    }
    force_command_t cmd{};
    cmd.utime = cmd.sample_utime = s->utime;
    for (int i = 0; i < 6; ++i) cmd.force_n[i] = hold_n_(i) + extra_n(i);
    safety_.Publish(cmd);
  }
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* s) {
    truth.push_back(*s);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* h) {
    if (h->name == "hw_bridge") health.push_back(*h);
  }

  StackConfig config_;
  std::unique_ptr<lcm::LCM> lcm_;
  test::FakeSafetySession safety_;
};

/// Runs the forger for `count` samples after 0.5 s of holding, then 0.5 s
/// more; returns the worst |zd| from the first forgery on.
double AttackAndWatch(Bus* bus, int count) {
  bus->SpinSamples(500, 5.0);
  const std::size_t from = bus->truth.size();
  bus->forgeries_left = count;
  bus->SpinSamples(static_cast<std::size_t>(count) + 500, 5.0);
  return bus->max_abs_qd(2, from);
}

// No key: one, then twenty 100 N forgeries from another session, then
// twenty copies of the real answer (its session, its seq) with 100 N.
TEST(HwBridgeTrust, ForgeriesWithoutTheSessionOrSeqAreDropped) {
  Device device(7908, 17900);
  ASSERT_TRUE(device.emulator.started() && device.bridge.started());
  Bus bus(device.url);
  bus.forger = [&bus](const sensor_t& s, test::FakeSafetySession& real) {
    bus.Forge(s.utime, real.session_id() + 1, 1'000'000 + s.seq, 100.0);
  };
  const double zd_one = AttackAndWatch(&bus, 1);
  const double zd_twenty = AttackAndWatch(&bus, 20);
  bus.forger = [&bus](const sensor_t& s, test::FakeSafetySession& real) {
    // After the real answer of the previous sample: its seq again.
    bus.Forge(s.utime, real.session_id(), real.next_seq() - 1, 100.0);
  };
  const double zd_replayed = AttackAndWatch(&bus, 20);
  bus.Spin(0.6);  // a heartbeat after the last forgery
  ASSERT_TRUE(bus.have_health());
  const health_t& h = bus.last_health();
  EXPECT_EQ(Counter(h, "rejected_command_wrong_session"), 21);
  EXPECT_EQ(Counter(h, "rejected_command_seq_not_increasing"), 20);
  EXPECT_EQ(Counter(h, "guard_trips"), 0);
  EXPECT_EQ(Counter(h, "sessions_adopted"), 1);
  EXPECT_LT(zd_one, 2e-3);
  EXPECT_LT(zd_twenty, 2e-3);
  EXPECT_LT(zd_replayed, 2e-3);
  std::printf(
      "[trust] hw, no key: max |zd| after 1 forgery %.2e, after 20 %.2e, after 20 replays %.2e "
      "m/s\n",
      zd_one, zd_twenty, zd_replayed);
}

// With a key: the forger has the session id and the next seq (it reads the
// bus) but cannot make the tag.
TEST(HwBridgeTrust, WithAKeyForgeriesWithoutAValidMacAreDropped) {
  const KeyFiles files;
  Device device(7909, 17902, files.overlay);
  ASSERT_TRUE(device.emulator.started() && device.bridge.started());
  Bus bus(device.url, MessageAuthenticator::FromKeyFile(files.key));
  bus.forger = [&bus](const sensor_t& s, test::FakeSafetySession& real) {
    bus.Forge(s.utime, real.session_id(), real.next_seq(), 100.0);
  };
  const double zd_one = AttackAndWatch(&bus, 1);
  const double zd_twenty = AttackAndWatch(&bus, 20);
  bus.Spin(0.6);
  ASSERT_TRUE(bus.have_health());
  const health_t& h = bus.last_health();
  EXPECT_EQ(Counter(h, "rejected_command_unauthentic"), 21);
  EXPECT_EQ(Counter(h, "guard_trips"), 0);
  EXPECT_GT(Counter(h, "commands_trusted"), 900);
  EXPECT_LT(zd_one, 2e-3);
  EXPECT_LT(zd_twenty, 2e-3);
  std::printf("[trust] hw, key: max |zd| after 1 forgery %.2e, after 20 %.2e m/s\n", zd_one,
              zd_twenty);
}

// The bridge's guard on its own pot readings: the session itself pushes
// beyond the speed cap; zero drive, latched, FAULT; a signed RESET clears
// it once the legs are held at rest inside their margins.
TEST(HwBridgeTrust, GuardTripsOnSpeedLatchesAndClearsOnAnAuthenticReset) {
  const KeyFiles files;
  MessageAuthenticator auth = MessageAuthenticator::FromKeyFile(files.key);
  Device device(7910, 17904, files.overlay);
  ASSERT_TRUE(device.emulator.started() && device.bridge.started());
  Bus bus(device.url, MessageAuthenticator::FromKeyFile(files.key));
  bus.SpinSamples(500, 5.0);
  bus.extra_n = Vector6d::Constant(10.0);
  const auto until = [&](const std::function<bool()>& done, double max_s) {
    const auto end = Clock::now() + std::chrono::duration<double>(max_s);
    while (!done() && Clock::now() < end) bus.Spin(0.01);
    return done();
  };
  ASSERT_TRUE(until(
      [&] { return bus.have_health() && Counter(bus.last_health(), "guard_tripped") == 1; }, 5.0));
  const health_t trip = bus.last_health();
  EXPECT_EQ(trip.state, static_cast<int8_t>(health_t::STATE_FAULT));
  EXPECT_NE(trip.last_error.find("speed"), std::string::npos) << trip.last_error;
  bus.Spin(0.3);
  ASSERT_FALSE(bus.truth.empty());
  EXPECT_LT(std::abs(bus.truth.back().qd[2]), 1e-3);  // held although the session pushes on
  const double peak_zd = bus.max_abs_qd(2);
  bus.extra_n = Vector6d::Zero();
  bus.SendReset(nullptr, 5, 1);  // unsigned: refused
  bus.Spin(0.6);
  EXPECT_EQ(Counter(bus.last_health(), "guard_tripped"), 1);
  EXPECT_GE(Counter(bus.last_health(), "rejected_operator_unauthentic"), 1);
  bus.SendReset(&auth, 5, 2);
  EXPECT_TRUE(until([&] { return Counter(bus.last_health(), "guard_tripped") == 0; }, 3.0));
  EXPECT_GT(Counter(bus.last_health(), "guard_frames"), 100);
  std::printf("[trust] hw guard: %s; peak |zd| %.3f m/s\n", trip.last_error.c_str(), peak_zd);
}

}  // namespace
}  // namespace stewart
