// stewart_replay on inputs made here: bad input exits 2 with a message that
// names the problem; a synthetic run whose safe commands the safety process's
// own class made replays bit-identically (fallbacks counted apart), and
// a one-ulp change of one recorded command makes --expect-identical exit 1;
// messages the logger lost are found and left out; the controller's clock
// is recovered when the log lacks its first commands.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "stewart/common/health_counters.h"
#include "stewart/config/config_loader.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/controller/controller.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/signal_messages.h"
#include "stewart/safety/diagnostics_lcm.h"
#include "stewart/safety/safety_process.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/lcm_messages.h"

namespace stewart {
namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

CommandResult RunReplay(const std::string& args) {
  CommandResult r;
  const std::string command = std::string(STEWART_REPLAY_PATH) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) r.output.append(buffer, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

constexpr int kSamples = 200;
constexpr int kInitializing = 5;  // first samples: estimator initialising -> node fallback
// The estimates pause before this sample (the sensor stream stalled) longer
// than safety.stale_age_s: the watchdog, judged in state time, answers it with
// a fallback before its nominal command arrives.
constexpr int kStaleSample = 180;
constexpr int64_t kPauseUs = 25'000;
constexpr const char* kStallReason = "safety process stalled: a state waited 140 ms to be read";

class ReplayCli : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/stewart_replay_cli_XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr) << std::strerror(errno);
    root_ = dir;
  }
  void TearDown() override {
    if (HasFailure()) {
      std::printf("kept: %s\n", root_.c_str());
      return;
    }
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }

  /// A run folder as launch.sh makes it, with a log written here: estimates
  /// and nominal commands fed to the safety process's class as the node
  /// feeds it (closed form), its safe commands and diagnostics as the node
  /// publishes them, each in the order the logger would receive it. With
  /// `tamper_sample` >= 0 that sample's recorded force 0 is one ulp off;
  /// samples [drop_from, drop_from + drop_count) are left out of the log, as
  /// lcm-logger loses a burst (the process still had them); with
  /// `tamper_case_sample` >= 0 that sample's recorded diagnostics name
  /// another case; with `restart_sample` >= 0 the live safety process
  /// restarts before that sample (a new process: seq from 0, DISARMED); with
  /// `node_fault_sample` >= 0 the live node reports a fault (a stall) to its
  /// supervisor after that sample's state arrived and before it is read, and
  /// announces it on the supervisor channel unless `announce_fault` is false.
  std::string MakeRun(const std::string& name, int tamper_sample = -1, int drop_from = -1,
                      int drop_count = 0, int tamper_case_sample = -1, int restart_sample = -1,
                      int node_fault_sample = -1, bool announce_fault = true) {
    const std::string run = root_ + "/" + name;
    fs::create_directories(run);
    const std::string config_path = std::string(STEWART_SOURCE_DIR) + "/config/platform.yaml";
    {
      // A simulated run: the supervisor arms by itself (as tools/launch.sh
      // has it in simulation).
      std::ifstream in(config_path);
      std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      const std::string off = "auto_arm: false";
      EXPECT_NE(text.find(off), std::string::npos);
      if (text.find(off) != std::string::npos)
        text.replace(text.find(off), off.size(), "auto_arm: true");
      std::ofstream(run + "/config.yaml") << text;
    }
    std::ofstream(run + "/run.yaml") << "variant: closed_form\n";
    StackConfig config = LoadStackConfig(run + "/config.yaml");
    config.safety.variant = SafetyVariant::kClosedForm;
    auto counters_ptr = std::make_unique<HealthCounters>("safety");
    auto process_ptr =
        std::make_unique<safety::SafetyProcess>(config.platform, config.safety, config.actuators,
                                                config.supervisor, nullptr, counters_ptr.get());
    const ChannelNames& ch = config.lcm.channels;

    lcm::LogFile log(run + "/log.lcm", "w");
    EXPECT_TRUE(log.good());
    int64_t timestamp = 1'000'000;
    auto publish = [&](const safety::SafetyOutput& out, int k, bool dropped) {
      force_command_t safe{};
      ToMessage(out.command, &safe);
      if (k == tamper_sample) safe.force_n[0] = std::nextafter(safe.force_n[0], 1e9);
      safety_diagnostics_t diag{};
      safety::FillDiagnosticsMessage(process_ptr->filter(), out, &diag);
      if (k == tamper_case_sample) diag.active_case = diag.active_case == 0 ? 1 : 0;
      if (dropped) return;
      test::AppendToLog(&log, ch.command_safe, safe, timestamp++);
      test::AppendToLog(&log, ch.safety_diagnostics, diag, timestamp++);
    };
    int64_t nominal_seq = 0;
    for (int k = 0; k < kSamples; ++k) {
      if (k == restart_sample) {
        process_ptr.reset();
        counters_ptr = std::make_unique<HealthCounters>("safety");
        process_ptr = std::make_unique<safety::SafetyProcess>(config.platform, config.safety,
                                                              config.actuators, config.supervisor,
                                                              nullptr, counters_ptr.get());
      }
      safety::SafetyProcess& process = *process_ptr;
      const bool dropped = k >= drop_from && k < drop_from + drop_count;
      const int64_t utime = 1000 * (k + 1) + (k >= kStaleSample ? kPauseUs : 0);
      const double t = 1e-3 * k;
      state_t state{};
      state.utime = state.sample_utime = utime;
      state.seq = k;
      const double q[6] = {0.1 + 0.02 * t, 0.05 * std::sin(t), 0.45, 0.01, -0.02, 0.0};
      const double qd[6] = {0.0145, 0.01 * std::cos(t), 0.009, 0.0, 0.05, -0.01};
      std::copy(q, q + 6, state.q);
      std::copy(qd, qd + 6, state.qd);
      state.status = k < kInitializing ? int32_t{state_t::STATUS_INITIALIZING}
                                       : int32_t{state_t::STATUS_VALID};
      if (!dropped) test::AppendToLog(&log, ch.state_estimate, state, timestamp++);
      if (k == node_fault_sample) {
        // As SafetyNode::Fault: the supervisor hears it, the node announces it.
        safety::Supervisor& supervisor = process.supervisor();
        supervisor.OnFault(kStallReason);
        supervisor_state_t announcement{};
        announcement.utime = supervisor.utime();
        announcement.sample_utime = supervisor.sample_utime();
        announcement.session_id = 7;
        announcement.state = static_cast<int8_t>(supervisor.state());
        announcement.reason = supervisor.reason();
        announcement.node_faults = supervisor.faults_received();
        announcement.last_node_fault = supervisor.last_fault_received();
        if (announce_fault) test::AppendToLog(&log, ch.supervisor, announcement, timestamp++);
      }
      safety::SafetyOutput out;
      if (process.OnState(FromMessage(state), &out)) publish(out, k, dropped);
      if (k < kInitializing) continue;  // the controller waits for a valid estimate

      force_command_t nominal{};
      nominal.utime = nominal.sample_utime = utime;
      nominal.seq = nominal_seq++;
      for (int i = 0; i < 6; ++i) nominal.force_n[i] = 1.5 + 0.3 * std::sin(t + i);
      if (!dropped) test::AppendToLog(&log, ch.command_nominal, nominal, timestamp++);
      if (process.OnNominal(FromMessage(nominal), &out)) publish(out, k, dropped);
    }
    if (restart_sample < 0 && node_fault_sample < 0) {
      // The process made what the assertions below count.
      EXPECT_EQ(counters_ptr->counter("fallback_commands"), kInitializing + 1);
      EXPECT_EQ(counters_ptr->counter("rejected_nominal_already_answered"), 1);
    }
    return run;
  }

  /// stewart_replay on `run` with `args` and --json: the JSON it wrote (null
  /// if none); its exit code and output in `*result`.
  nlohmann::json ReplayJson(const std::string& run, const std::string& args,
                            CommandResult* result) {
    const std::string json_path = root_ + "/replay.json";
    *result = RunReplay(run + " " + args + " --json " + json_path);
    return fs::exists(json_path) ? ReadJson(json_path) : nlohmann::json();
  }

  static Vector6d FromArrayOf(const double (&a)[6]) { return Eigen::Map<const Vector6d>(a); }

  std::string root_;
};

// A log whose first messages the logger lost: the controller's commands
// (computed here on a scenario that changes from t = 0) still replay
// bit-identically from the inferred start of its clock.
TEST_F(ReplayCli, ControllerClockRecoveredWhenTheLogLacksTheStart) {
  constexpr int kStates = 300;
  constexpr int kLost = 40;  // the log lacks the first kLost estimates and commands
  const std::string run = root_ + "/run";
  fs::create_directories(run);
  const std::string config_path = std::string(STEWART_SOURCE_DIR) + "/config/platform.yaml";
  fs::copy_file(config_path, run + "/config.yaml");
  std::ofstream(run + "/scenario.yaml")
      << "name: wave\nduration_s: 1.0\nsegments:\n"
      << "  - {start_s: 0.0, type: sine, center: [0.0, 0.0, 0.4, 0.0, 0.0, 0.0], "
      << "amplitude: [0.02, 0.01, 0.0, 0.0, 0.0, 0.0], period_s: 0.2, "
      << "phase_deg: [0.0, 90.0, 0.0, 0.0, 0.0, 0.0]}\n";
  const StackConfig config = LoadStackConfig(config_path);
  Controller controller(config.platform, config.controller, config.home_pose,
                        LoadScenario(run + "/scenario.yaml"));
  {
    lcm::LogFile log(run + "/log.lcm", "w");
    ASSERT_TRUE(log.good());
    for (int k = 0; k < kStates; ++k) {
      state_t state{};
      state.utime = state.sample_utime = 1000 * (k + 1);
      state.seq = k;
      state.q[2] = 0.4 + 1e-3 * std::sin(0.05 * k);
      state.qd[0] = 0.01 * std::cos(0.05 * k);
      state.status = state_t::STATUS_VALID;
      ControllerOutput out;
      ASSERT_EQ(controller.Step(state.utime, FromArrayOf(state.q), FromArrayOf(state.qd), &out),
                StepStatus::kOk);
      force_command_t nominal{};
      nominal.utime = nominal.sample_utime = state.sample_utime;
      nominal.seq = k;
      for (int i = 0; i < 6; ++i) nominal.force_n[i] = out.force_n(i);
      if (k < kLost) continue;
      test::AppendToLog(&log, config.lcm.channels.state_estimate, state, 1000 + k);
      test::AppendToLog(&log, config.lcm.channels.command_nominal, nominal, 1000 + k);
    }
  }
  CommandResult r;
  const nlohmann::json j = ReplayJson(run, "--controller --expect-identical", &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json& c = j.at("controller");
  EXPECT_TRUE(c.at("time_origin_inferred").get<bool>());
  EXPECT_EQ(c.at("time_origin_utime"), 1000);
  EXPECT_EQ(c.at("compared"), kStates - kLost);
  EXPECT_EQ(c.at("identical"), kStates - kLost);
  EXPECT_NE(r.output.find("inferred"), std::string::npos) << r.output;
}

TEST_F(ReplayCli, MissingRunFolderExitsTwo) {
  const CommandResult r = RunReplay(root_ + "/no-such-run");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no run folder or LCM log"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(root_ + "/no-such-run"), std::string::npos) << r.output;
}

TEST_F(ReplayCli, MissingLogExitsTwo) {
  const std::string run = MakeRun("run");
  fs::remove(run + "/log.lcm");
  const CommandResult r = RunReplay(run + " --json " + root_ + "/out.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no LCM log '" + run + "/log.lcm'"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(root_ + "/out.json"));
}

TEST_F(ReplayCli, UnreadableLogExitsTwo) {
  const std::string run = MakeRun("run");
  std::ofstream(run + "/log.lcm", std::ios::trunc) << "this is not an LCM log\n";
  const CommandResult r = RunReplay(run);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("holds no LCM event"), std::string::npos) << r.output;
}

TEST_F(ReplayCli, BadFlagsExitTwo) {
  const std::string run = MakeRun("run");
  for (const char* args : {" --variant fastest", " --k-velocity -3", " --qp-solver mosek",
                           " --no-such-flag", " --controller --scenario /no/such.yaml"}) {
    const CommandResult r = RunReplay(run + args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
  }
}

TEST_F(ReplayCli, SyntheticRunReplaysBitIdentically) {
  const std::string run = MakeRun("run");
  CommandResult r;
  const nlohmann::json j = ReplayJson(run, "--expect-identical", &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("variant"), "closed_form");
  EXPECT_EQ(s.at("variant_source"), "run.yaml");
  EXPECT_EQ(s.at("nominal_commands"), kSamples - kInitializing);
  EXPECT_EQ(s.at("answered_by_fallback"), 1);
  EXPECT_EQ(s.at("compared"), kSamples - kInitializing - 1);
  EXPECT_EQ(s.at("identical"), s.at("compared"));
  EXPECT_EQ(s.at("max_abs_diff_n"), 0.0);
  EXPECT_EQ(s.at("fallback").at("recorded"), kInitializing + 1);
  EXPECT_EQ(s.at("fallback").at("stale_input"), 1);
  EXPECT_EQ(s.at("fallback").at("invalid_state"), kInitializing);
  EXPECT_EQ(s.at("fallback").at("identical"), kInitializing + 1);
  EXPECT_EQ(s.at("compute_ns").at("replayed").at("count"), s.at("compared"));
  EXPECT_EQ(s.at("compute_ns").at("recorded").at("count"), s.at("compared"));
  EXPECT_TRUE(j.at("identical").get<bool>());
  EXPECT_TRUE(j.at("log_gaps").empty());
  EXPECT_NE(r.output.find("bit-identical"), std::string::npos) << r.output;
}

TEST_F(ReplayCli, MessagesLostByTheLoggerAreFoundAndNotCompared) {
  constexpr int kDropFrom = 120, kDropCount = 7;
  const std::string run = MakeRun("run", -1, kDropFrom, kDropCount);
  CommandResult r;
  const nlohmann::json j = ReplayJson(run, "--expect-identical", &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const StackConfig config = LoadStackConfig(run + "/config.yaml");
  for (const std::string& channel :
       {config.lcm.channels.state_estimate, config.lcm.channels.command_nominal,
        config.lcm.channels.command_safe, config.lcm.channels.safety_diagnostics}) {
    ASSERT_TRUE(j.at("log_gaps").contains(channel)) << channel << ": " << j.at("log_gaps");
    const nlohmann::json& gaps = j.at("log_gaps").at(channel);
    EXPECT_EQ(gaps.at("missing"), kDropCount) << channel;
    EXPECT_EQ(gaps.at("gaps"), 1) << channel;
    EXPECT_EQ(gaps.at("intact_until_utime"), 1000 * kDropFrom) << channel;
  }
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("compared"), kSamples - kInitializing - 1 - kDropCount);
  EXPECT_EQ(s.at("identical"), s.at("compared"));
  EXPECT_NE(r.output.find("log gap " + config.lcm.channels.command_safe +
                          ": 7 messages published but not in the log"),
            std::string::npos)
      << r.output;
}

// The replayed diagnostics are compared too: one recorded case changed makes
// its step differ although the command is bit-identical.
TEST_F(ReplayCli, DifferentRecordedDiagnosticsFailExpectIdentical) {
  CommandResult r;
  const nlohmann::json j = ReplayJson(MakeRun("run", -1, -1, 0, 150), "--expect-identical", &r);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("diagnostics_differ"), 1);
  EXPECT_EQ(s.at("flags_differ"), 0);
  EXPECT_EQ(s.at("max_abs_diff_n"), 0.0);
  EXPECT_EQ(s.at("identical").get<long>(), s.at("compared").get<long>() - 1);
}

// A burst lost by the logger longer than safety.stale_age_s: the replayed
// watchdog fires at the first estimate after it (the live process had the
// nominal commands the log lacks); that fallback is counted, not compared.
TEST_F(ReplayCli, WatchdogWhereTheLogLacksNominalCommandsIsNotCompared) {
  constexpr int kDropCount = 30;
  CommandResult r;
  const nlohmann::json j =
      ReplayJson(MakeRun("run", -1, 130, kDropCount), "--expect-identical", &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("log_gap"), 1);
  EXPECT_EQ(s.at("compared"), kSamples - kInitializing - 1 - kDropCount - 1);
  EXPECT_EQ(s.at("identical"), s.at("compared"));
  EXPECT_EQ(s.at("fallback").at("identical"), kInitializing + 1);
  EXPECT_NE(r.output.find("1 watchdog fallbacks of the replay"), std::string::npos) << r.output;
}

// The live safety process restarted mid-run (seq from 0, DISARMED, arming
// again); the replay's process ran on. The restart is named before any
// difference, with its time, and the differences after it are attributed to
// it while still counted (--expect-identical fails).
TEST_F(ReplayCli, ARestartedProcessIsNamedFirstAndItsDifferencesAttributedToIt) {
  constexpr int kRestart = 100;
  const std::string run = MakeRun("run", -1, -1, 0, -1, kRestart);
  CommandResult r;
  const nlohmann::json j = ReplayJson(run, "--expect-identical", &r);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const StackConfig config = LoadStackConfig(run + "/config.yaml");
  const std::string safe = config.lcm.channels.command_safe;
  EXPECT_TRUE(j.at("log_gaps").empty()) << j.at("log_gaps");
  ASSERT_EQ(j.at("log_restarts").size(), 2u) << j.at("log_restarts");
  const nlohmann::json* restart = nullptr;
  for (const nlohmann::json& e : j.at("log_restarts")) {
    if (e.at("stream") == safe) restart = &e;
  }
  ASSERT_NE(restart, nullptr) << j.at("log_restarts");
  EXPECT_EQ(restart->at("utime"), 1000 * (kRestart + 1));
  EXPECT_EQ(restart->at("seq"), 0);
  EXPECT_GT(restart->at("previous_seq").get<long>(), 0);
  const nlohmann::json& s = j.at("safety");
  const long differing = j.at("differing").get<long>();
  EXPECT_GT(differing, 0);
  EXPECT_EQ(j.at("differing_after_restart").get<long>(), differing);
  EXPECT_GT(s.at("compared_after_restart").get<long>(), 0);
  // Before the restart, the replay reproduced every command.
  EXPECT_EQ(s.at("identical").get<long>(),
            s.at("compared").get<long>() - s.at("differing_after_restart").get<long>());
  const size_t named = r.output.find("restart " + safe + ": seq fell back from");
  ASSERT_NE(named, std::string::npos) << r.output;
  EXPECT_LT(named, r.output.find("Safety filter:")) << r.output;
  EXPECT_NE(r.output.find(std::to_string(differing) + " of them after the restart of"),
            std::string::npos)
      << r.output;
}

// The live node held the platform for a fault judged on its wall clock (a
// stall, here): nothing in the states or commands shows it. The replay's
// supervisor hears it from the recorded announcement, between the same two
// outputs, so the HOLD's commands replay bit-identically.
TEST_F(ReplayCli, AFaultTheNodeAnnouncedIsHeardAtTheSampleItFollowed) {
  constexpr int kFault = 100;
  CommandResult r;
  const nlohmann::json j =
      ReplayJson(MakeRun("run", -1, -1, 0, -1, -1, kFault), "--expect-identical", &r);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("node_faults").at("source"), "recorded");
  ASSERT_EQ(s.at("node_faults").at("heard").size(), 1u) << s.at("node_faults");
  const nlohmann::json& fault = s.at("node_faults").at("heard").at(0);
  EXPECT_EQ(fault.at("reason"), kStallReason);
  EXPECT_EQ(fault.at("after_sample_utime"), 1000 * kFault);  // sample kFault - 1
  // From the fault on, the supervisor's stop answers every sample but the
  // watchdog's (kStaleSample: a stale input first).
  EXPECT_EQ(s.at("fallback").at("supervisor_stop"), kSamples - kFault - 1);
  EXPECT_EQ(s.at("fallback").at("stale_input"), 1);
  EXPECT_EQ(s.at("fallback").at("identical"), s.at("fallback").at("compared"));
  EXPECT_EQ(s.at("identical"), s.at("compared"));
  EXPECT_NE(
      r.output.find(std::string("node fault            after sample 0.100000 s: ") + kStallReason),
      std::string::npos)
      << r.output;
}

// The same run without the announcement (a log that lacks it): the replay
// cannot know of the fault and its commands differ from the HOLD's.
TEST_F(ReplayCli, AFaultTheLogDoesNotAnnounceIsNotReplayed) {
  constexpr int kFault = 100;
  CommandResult r;
  const nlohmann::json j =
      ReplayJson(MakeRun("run", -1, -1, 0, -1, -1, kFault, false), "--expect-identical", &r);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("node_faults").at("source"), "heartbeats");
  EXPECT_TRUE(s.at("node_faults").at("heard").empty());
  EXPECT_LT(s.at("fallback").at("identical").get<long>(),
            s.at("fallback").at("compared").get<long>());
}

TEST_F(ReplayCli, OneUlpDifferenceFailsExpectIdentical) {
  constexpr int kTampered = 150;
  const std::string run = MakeRun("run", kTampered);
  CommandResult r;
  const nlohmann::json j = ReplayJson(run, "--expect-identical", &r);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const nlohmann::json& s = j.at("safety");
  EXPECT_EQ(s.at("identical").get<long>(), s.at("compared").get<long>() - 1);
  EXPECT_GT(s.at("max_abs_diff_n").get<double>(), 0.0);
  EXPECT_LT(s.at("max_abs_diff_n").get<double>(), 1e-12);
  EXPECT_EQ(s.at("worst_sample_utime"), 1000 * (kTampered + 1));
  EXPECT_EQ(j.at("differing"), 1);
  // Without --expect-identical the same difference is only reported.
  EXPECT_EQ(RunReplay(run).exit_code, 0);
}

}  // namespace
}  // namespace stewart
