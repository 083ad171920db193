// The viewer's page in a real browser (headless Chromium over the DevTools
// protocol, tests/viewer/browser/browser_check.js), against the lockstep
// stack on the bus and against a recorded paper run. Chromium, node and the
// pinned puppeteer-core are installed by tools/setup.sh; when one is
// missing the test fails, naming it. LCM ports 7970-7972, HTTP 18970-18972.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

const std::string kBrowserDir = STEWART_SOURCE_DIR "/tests/viewer/browser";

std::string FindOnPath(const std::string& program) {
  const char* path = getenv("PATH");
  std::string dirs = path != nullptr ? path : "/usr/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = dirs.find(':', start);
    const std::string candidate =
        dirs.substr(start, end == std::string::npos ? std::string::npos : end - start) + "/" +
        program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return "";
}

/// What the browser check needs; "" when all is there, else what is missing.
std::string MissingBrowserTools() {
  std::string missing;
  if (access("/usr/bin/chromium", X_OK) != 0) missing += " /usr/bin/chromium (Debian: chromium);";
  if (FindOnPath("node").empty()) missing += " node (Debian: nodejs);";
  if (access((kBrowserDir + "/node_modules/puppeteer-core/package.json").c_str(), R_OK) != 0) {
    missing +=
        " " + kBrowserDir + "/node_modules/puppeteer-core (npm ci from its package-lock.json);";
  }
  return missing;
}

/// The prefix that runs a process of a real-time loop as tools/launch.sh
/// does: on the last CPU, SCHED_FIFO 50 (empty where this machine or user
/// cannot). A browser starting beside a loop without it once stalled
/// plant_sim 65 ms, past its command timeout: the supervisor held, as it
/// must, before the page could press anything.
std::vector<std::string> RealTimeLoopPrefix() {
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  if (cpus < 2) return {};
  const std::string cpu = std::to_string(cpus - 1);
  if (test::Shell("chrt -f 50 true && taskset -c " + cpu + " true") != 0) return {};
  return {"/usr/bin/taskset", "-c", cpu, "chrt", "-f", "50"};
}

/// Runs browser_check.js; its JSON result, or a failure naming why. With
/// `beside_real_time_loop` the browser keeps off the loop's CPU.
nlohmann::json RunBrowserCheck(const std::string& mode, int http_port,
                               bool beside_real_time_loop = false) {
  const std::string out = ::testing::TempDir() + "viewer_browser_" + mode + ".json";
  std::remove(out.c_str());
  std::vector<std::string> argv = {FindOnPath("node"), kBrowserDir + "/browser_check.js", mode,
                                   "http://127.0.0.1:" + std::to_string(http_port) + "/", out};
  if (beside_real_time_loop) {
    const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    argv.insert(argv.begin(), {"/usr/bin/taskset", "-c", "0-" + std::to_string(cpus - 2)});
  }
  test::ChildProcess check(argv);
  EXPECT_TRUE(check.started());
  const int code = check.Wait(std::chrono::seconds(90));
  EXPECT_EQ(code, 0) << "browser_check.js " << mode << " failed (its message is above)";
  std::ifstream in(out);
  if (!in) return nullptr;
  return nlohmann::json::parse(in, nullptr, false);
}

/// Every state estimate on the bus, by utime, received on a thread of its own.
class EstimateRecorder {
 public:
  EstimateRecorder(const std::string& url, const ChannelNames& channels) : receiver_(url) {
    receiver_.Subscribe(channels.state_estimate, &EstimateRecorder::On, this);
    receiver_.Subscribe(channels.health, &EstimateRecorder::OnHealth, this);
    thread_ = std::thread([this] {
      while (!stop_) receiver_.HandleTimeout(20);
    });
  }
  ~EstimateRecorder() {
    stop_ = true;
    thread_.join();
  }
  bool Find(int64_t utime, std::array<double, 6>* q) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = by_utime_.find(utime);
    if (it == by_utime_.end()) return false;
    *q = it->second;
    return true;
  }
  size_t size() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return by_utime_.size();
  }
  /// Waits until every named process has sent a heartbeat.
  bool WaitForHeartbeats(const std::set<std::string>& names, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (std::includes(heard_.begin(), heard_.end(), names.begin(), names.end())) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
    std::array<double, 6> q;
    std::copy(std::begin(msg->q), std::end(msg->q), q.begin());
    const std::lock_guard<std::mutex> lock(mutex_);
    by_utime_[msg->utime] = q;
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    heard_.insert(msg->name);
  }
  LcmReceiver receiver_;
  std::mutex mutex_;
  std::set<std::string> heard_;
  std::unordered_map<int64_t, std::array<double, 6>> by_utime_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::string AutoArmOverlay(const std::string& name) {
  const std::string overlay = ::testing::TempDir() + name;
  std::ofstream(overlay) << "supervisor:\n  auto_arm: true\n";
  return overlay;
}

bool WaitForPort(int port, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    const std::string cmd =
        "bash -c 'exec 3<>/dev/tcp/127.0.0.1/" + std::to_string(port) + "' 2>/dev/null";
    if (std::system(cmd.c_str()) == 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

TEST(ViewerBrowser, LivePageShowsTheStateItWasSentAndKeepsUpdating) {
  const std::string missing = MissingBrowserTools();
  ASSERT_TRUE(missing.empty()) << "the browser test needs:" << missing << " run tools/setup.sh";
  test::LauncherLock lock;
  constexpr int kLcmPort = 7970;
  constexpr int kHttpPort = 18970;
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kLcmPort);
  EstimateRecorder recorder(url, config.lcm.channels);
  const std::vector<std::string> common = {
      "--lcm-url", url, "--overlay", AutoArmOverlay("viewer_auto_arm.yaml"), "--log-level", "warn"};
  auto with = [&](std::vector<std::string> head) {
    head.insert(head.end(), common.begin(), common.end());
    return head;
  };
  test::ChildProcess viewer(with({VIEWER_PATH, "--port", std::to_string(kHttpPort)}));
  test::ChildProcess safety(with({SAFETY_PATH}));
  test::ChildProcess controller(with({CONTROLLER_PATH, "--scenario", "paper"}));
  test::ChildProcess estimator(with({ESTIMATOR_PATH}));
  ASSERT_TRUE(viewer.started() && safety.started() && controller.started() && estimator.started());
  // The plant last, once the stack listens: a first sample it sends before
  // then is lost, and lockstep would wait for its answer to the end.
  ASSERT_TRUE(recorder.WaitForHeartbeats({"safety", "controller", "estimator"}, 15.0))
      << "the stack did not come up";
  // Lockstep, long enough to outlast the browser's start (~10x real time).
  test::ChildProcess plant(with({PLANT_SIM_PATH, "--mode", "lockstep", "--duration", "3000"}));
  ASSERT_TRUE(plant.started());
  ASSERT_TRUE(WaitForPort(kHttpPort, 10.0)) << "stewart_viewer did not listen on " << kHttpPort;

  const auto t0 = std::chrono::steady_clock::now();
  const nlohmann::json result = RunBrowserCheck("live", kHttpPort);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(result.is_object()) << "browser_check.js wrote no result";
  EXPECT_TRUE(result["console_errors"].empty()) << result["console_errors"].dump(1);
  EXPECT_TRUE(result["page_errors"].empty()) << result["page_errors"].dump(1);
  EXPECT_FALSE(result["operator"].get<bool>()) << "read-only without --operator";
  EXPECT_TRUE(result["buttons_hidden"].get<bool>()) << "operator buttons shown read-only";
  const auto& samples = result["samples"];
  ASSERT_GE(samples.size(), 3u);
  int64_t previous_utime = -1;
  for (const auto& s : samples) {
    const int64_t utime = s["utime_us"].get<int64_t>();
    std::array<double, 6> sent{};
    ASSERT_TRUE(recorder.Find(utime, &sent))
        << "the page shows a state at " << utime << " us that was never on the bus";
    for (int i = 0; i < 6; ++i) {
      // JSON carries doubles exactly (shortest round-trip form).
      EXPECT_EQ(s["q"][i].get<double>(), sent[static_cast<size_t>(i)])
          << "q[" << i << "] at " << utime;
    }
    EXPECT_GT(utime, previous_utime) << "the page stopped updating";
    previous_utime = utime;
  }
  EXPECT_EQ(viewer.Stop(SIGTERM), 0) << "stewart_viewer did not stop cleanly";
  std::printf(
      "[viewer] live: %zu samples checked against %zu states on the bus; browser check %.1f s\n",
      samples.size(), recorder.size(), seconds);
}

TEST(ViewerBrowser, WithOperatorTheHoldButtonHoldsThePlatform) {
  const std::string missing = MissingBrowserTools();
  ASSERT_TRUE(missing.empty()) << "the browser test needs:" << missing << " run tools/setup.sh";
  test::LauncherLock lock;
  constexpr int kLcmPort = 7972;
  constexpr int kHttpPort = 18972;
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kLcmPort);
  const std::vector<std::string> common = {
      "--lcm-url",   url,   "--overlay", AutoArmOverlay("viewer_operator_auto_arm.yaml"),
      "--log-level", "warn"};
  auto with = [&](std::vector<std::string> head) {
    head.insert(head.end(), common.begin(), common.end());
    return head;
  };
  // Real time: the supervisor's answer comes while the stack runs; the loop
  // runs as tools/launch.sh runs it, where it can.
  const std::vector<std::string> loop = RealTimeLoopPrefix();
  const auto in_loop = [&](std::vector<std::string> argv) {
    argv = with(std::move(argv));
    argv.insert(argv.begin(), loop.begin(), loop.end());
    return argv;
  };
  test::ChildProcess viewer(with({VIEWER_PATH, "--port", std::to_string(kHttpPort), "--operator"}));
  test::ChildProcess safety(in_loop({SAFETY_PATH}));
  test::ChildProcess controller(in_loop({CONTROLLER_PATH, "--scenario", "paper"}));
  test::ChildProcess estimator(in_loop({ESTIMATOR_PATH}));
  test::ChildProcess plant(in_loop({PLANT_SIM_PATH, "--mode", "realtime"}));
  std::printf("[viewer] operator: the loop %s\n",
              loop.empty() ? "without real-time priority (not allowed here)"
                           : ("on CPU " + loop[2] + ", SCHED_FIFO 50").c_str());
  ASSERT_TRUE(viewer.started() && safety.started() && controller.started() && estimator.started() &&
              plant.started());
  ASSERT_TRUE(WaitForPort(kHttpPort, 10.0)) << "stewart_viewer did not listen on " << kHttpPort;
  const nlohmann::json result = RunBrowserCheck("operator", kHttpPort, !loop.empty());
  ASSERT_TRUE(result.is_object()) << "browser_check.js wrote no result";
  EXPECT_TRUE(result["console_errors"].empty()) << result["console_errors"].dump(1);
  EXPECT_TRUE(result["page_errors"].empty()) << result["page_errors"].dump(1);
  EXPECT_FALSE(result["buttons_hidden"].get<bool>()) << "no buttons with --operator";
  EXPECT_EQ(result["supervisor"], "HOLD");
  EXPECT_NE(result["reply"].get<std::string>().find("accepted"), std::string::npos)
      << result["reply"];
  // Seen on the operator channel too, its MAC verified (no "does not verify").
  ASSERT_TRUE(result["last_operator_command"].is_string());
  EXPECT_EQ(result["last_operator_command"].get<std::string>().find("does not verify"),
            std::string::npos)
      << result["last_operator_command"];
  EXPECT_EQ(viewer.Stop(SIGTERM), 0) << "stewart_viewer did not stop cleanly";
}

TEST(ViewerBrowser, ScrubbingARecordedPaperRunTo15sShowsTheYPhase) {
  const std::string missing = MissingBrowserTools();
  ASSERT_TRUE(missing.empty()) << "the browser test needs:" << missing << " run tools/setup.sh";
  constexpr int kHttpPort = 18971;
  std::string folder = "/tmp/stewart_viewer_scrub_XXXXXX";
  ASSERT_NE(mkdtemp(folder.data()), nullptr);
  const std::string run = folder + "/run";
  // The whole test under the lock, the browser too: software WebGL takes a
  // core, and a lockstep stack sharing the other would lose messages.
  test::LauncherLock lock;
  {
    setenv("STEWART_BUILD_DIR", STEWART_BUILD_DIR, 1);
    test::ChildProcess launch({"/bin/bash", STEWART_SOURCE_DIR "/tools/launch.sh", "--no-build",
                               "--no-report", "--scenario", "paper", "--duration", "20", "--out",
                               run, "--lcm-url", PrivateLcmUrl(7971)});
    ASSERT_EQ(launch.Wait(std::chrono::seconds(120)), 0) << "tools/launch.sh failed";
  }
  test::ChildProcess viewer({VIEWER_PATH, "--log", run + "/log.lcm", "--port",
                             std::to_string(kHttpPort), "--log-level", "warn"});
  ASSERT_TRUE(WaitForPort(kHttpPort, 15.0)) << "stewart_viewer --log did not listen";
  const nlohmann::json result = RunBrowserCheck("scrub", kHttpPort);
  ASSERT_TRUE(result.is_object()) << "browser_check.js wrote no result";
  EXPECT_TRUE(result["console_errors"].empty()) << result["console_errors"].dump(1);
  EXPECT_TRUE(result["page_errors"].empty()) << result["page_errors"].dump(1);
  const auto& at = result["at_15"];
  ASSERT_FALSE(at["q"].is_null());
  EXPECT_NEAR(at["playback"]["t_s"].get<double>(), 15.0, 1e-6);
  EXPECT_LE(at["t_s"].get<double>(), 15.0);
  EXPECT_GT(at["t_s"].get<double>(), 14.99) << "the estimate shown is not the one at 15 s";
  // The scenario's y phase (10 <= t < 20 of motion time): y setpoint 0.1,
  // x back at 0, and the platform over towards y.
  ASSERT_FALSE(at["setpoint"].is_null());
  EXPECT_DOUBLE_EQ(at["setpoint"][1].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(at["setpoint"][0].get<double>(), 0.0);
  // y moves at most at its velocity limit (0.015 m/s): ~0.06 m by 15 s.
  EXPECT_GT(at["q"][1].get<double>(), 0.03);
  EXPECT_LT(std::abs(at["q"][0].get<double>()), 0.03);
  // A malformed message got a clear answer, and playing moves time on.
  ASSERT_TRUE(result["malformed_reply"].is_string()) << "no error reply to a malformed message";
  EXPECT_NE(result["malformed_reply"].get<std::string>().find("not JSON"), std::string::npos);
  EXPECT_GT(result["after_play"]["playback"]["t_s"].get<double>(), 16.0)
      << "play at 2x did not advance";
  EXPECT_EQ(viewer.Stop(SIGTERM), 0) << "stewart_viewer did not stop cleanly";
}

}  // namespace
}  // namespace stewart
