// tools/report.sh on run folders whose logs are written here: what a new
// user met. On hardware (no ground truth) the limits are judged on the
// estimate within its uncertainty and say so, the plant's own counters
// (hw_bridge's) are listed, every process's health, faults and the
// supervisor's HOLDs are there; a run whose plant died says so, with the
// counters of the plant's last heartbeat and its time; what the config does
// not limit is named with the extreme reached; an incomplete log and a
// restarted process are warned about first.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/health_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/lcm_messages.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

namespace fs = std::filesystem;

constexpr int kSamples = 2000;                    // 2 s at 1 kHz
constexpr int64_t kUtime0 = 5'000'000;            // stack time of the first sample (us)
constexpr int64_t kLog0 = 1'700'000'000'000'000;  // the logger's clock at the first sample

struct Heartbeat {
  std::string name;
  int8_t state = health_t::STATE_OK;
  std::vector<std::pair<std::string, int64_t>> counters;
  std::string latched_error;
};

Heartbeat Named(const std::string& name) {
  Heartbeat h;
  h.name = name;
  return h;
}

health_t HealthMessage(const Heartbeat& h, int64_t seq, int64_t utime) {
  health_t m{};
  m.utime = m.sample_utime = utime;
  m.seq = seq;
  m.name = h.name;
  m.state = m.worst_state = h.state;
  m.fault_latched = !h.latched_error.empty();
  m.latched_error = h.latched_error;
  m.messages_in = m.messages_out = 10 * seq;
  m.num_counters = static_cast<int32_t>(h.counters.size());
  for (const auto& [name, value] : h.counters) {
    m.counter_names.push_back(name);
    m.counter_values.push_back(value);
    m.counter_deltas.push_back(0);
  }
  return m;
}

class ReportTest : public WithRunFolder<::testing::Test> {
 protected:
  ReportTest() : WithRunFolder("stewart_report_test") {}

  /// config.yaml (the shipped config) and run.yaml (with wall_time_s when the
  /// launcher finished the run).
  StackConfig WriteRunFiles(bool launcher_finished) {
    fs::copy_file(std::string(STEWART_SOURCE_DIR) + "/config/platform.yaml",
                  run_folder_ + "/config.yaml", fs::copy_options::overwrite_existing);
    std::ofstream run(run_folder_ + "/run.yaml");
    run << "plant: test\nmode: realtime\nduration_s: 2\n";
    if (launcher_finished) run << "wall_time_s: 2.1\n";
    return LoadStackConfig(run_folder_ + "/config.yaml");
  }

  /// tools/report.sh on the run folder: report.md, or "" (with the output in
  /// the failure message) when it failed.
  std::string Report() {
    const std::string out = run_folder_ + "/report_sh.txt";
    const int code = Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) + " && STEWART_BUILD_DIR=" +
                           ShellQuote(STEWART_BUILD_DIR) + " tools/report.sh " +
                           ShellQuote(run_folder_) + " >" + ShellQuote(out) + " 2>&1");
    EXPECT_EQ(code, 0) << ReadFile(out);
    return ReadFile(run_folder_ + "/report.md");
  }
};

// Hardware with the emulator's place taken by nothing: no truth channel.
// y velocity goes 10 sigma of the estimate beyond its limit, x velocity 0.6
// sigma; x velocity reaches -0.184 m/s, which no limit bounds.
TEST_F(ReportTest, OnHardwareTheEstimateJudgesTheLimitsWithinItsUncertainty) {
  const StackConfig config = WriteRunFiles(true);
  const ChannelNames& ch = config.lcm.channels;
  {
    lcm::LogFile log(run_folder_ + "/log.lcm", "w");
    ASSERT_TRUE(log.good());
    const Heartbeat bridge{"hw_bridge",
                           health_t::STATE_OK,
                           {{"frames_received", 1998}, {"corrupt_frame", 2}, {"link_drops", 0}},
                           ""};
    const Heartbeat estimator{"estimator",
                              health_t::STATE_OK,
                              {{"reinitialisations", 1}},
                              "sensor samples stale for 0.2 s"};
    const Heartbeat others[] = {Named("controller"), Named("safety")};
    for (int k = 0; k < kSamples; ++k) {
      const int64_t utime = kUtime0 + 1000 * k;
      const int64_t stamp = kLog0 + 1000 * k;
      state_t s{};
      s.utime = s.sample_utime = utime;
      s.seq = k;
      s.q[2] = 0.4;
      s.qd[0] = k == 700 ? 0.0156 : (k == 900 ? -0.184 : 0.01);
      s.qd[1] = k == 800 ? 0.025 : 0.01;
      for (int i = 0; i < 6; ++i) {
        s.q_std[i] = 1e-4;
        s.qd_std[i] = 1e-3;
      }
      s.status = state_t::STATUS_VALID;
      AppendToLog(&log, ch.state_estimate, s, stamp);
      if (k % 500 == 0 || k == kSamples - 1) {
        const int64_t seq = k / 500 + (k == kSamples - 1 ? 1 : 0);
        AppendToLog(&log, ch.health, HealthMessage(bridge, seq, utime), stamp);
        AppendToLog(&log, ch.health, HealthMessage(estimator, seq, utime), stamp);
        for (const Heartbeat& h : others)
          AppendToLog(&log, ch.health, HealthMessage(h, seq, utime), stamp);
      }
      if (k == 0 || k == 1000) {
        supervisor_state_t sup{};
        sup.utime = sup.sample_utime = utime;
        sup.seq = k / 1000;
        sup.session_id = 7;
        sup.state = k == 0 ? supervisor_state_t::STATE_ARMED : supervisor_state_t::STATE_HOLD;
        sup.transitions = k == 0 ? 2 : 3;
        sup.reason = k == 0 ? "armed" : "estimator silent for 1.5 s";
        AppendToLog(&log, ch.supervisor, sup, stamp);
      }
    }
  }
  const std::string report = Report();
  for (const std::string& expected : {
           std::string("## Limits, judged on the estimate (STATE_EST): no ground truth in this "
                       "log"),
           std::string("Exceeded on the estimate (by more than its uncertainty): y velocity upper"),
           std::string("Beyond a limit within the estimate's uncertainty (not judged): x velocity "
                       "upper"),
           std::string("x velocity lower (min -0.184 m/s)"),
           std::string("- no ground truth in this log (on hardware there is none)"),
           // hw_bridge's own counters, with the time of its last heartbeat.
           std::string("Plant counters (hw_bridge, its last heartbeat, at t = 1.999 s, state OK"),
           std::string("frames_received 1998, corrupt_frame 2, link_drops 0"),
           // Every process's health and faults; the supervisor's HOLD and why.
           std::string("## Process health"),
           std::string("| estimator | ok | yes: sensor samples stale for 0.2 s |"),
           std::string("- estimator, t = 0.000 s: sensor samples stale for 0.2 s"),
           std::string("- hw_bridge (t = 1.999 s): messages in 40, out 40, rejected 0; "
                       "frames_received 1998"),
           // Stack times from the first state, as every t of the report (a
           // real-time run's stack time is the epoch's).
           std::string("| 1.000 | HOLD | estimator silent for 1.5 s |"),
           std::string("HOLD / ESTOP: 1: HOLD at 1.000 s (estimator silent for 1.5 s)"),
       }) {
    EXPECT_NE(report.find(expected), std::string::npos) << "missing: " << expected << "\n"
                                                        << report;
  }
  EXPECT_EQ(report.find("Exceeded: none"), std::string::npos) << report;
}

// plant_sim died 0.5 s into the run (no STOPPED heartbeat, its heartbeats
// stop) while the others went on; the launcher did not finish; the log lacks
// 10 estimates and the controller restarted at 1 s.
TEST_F(ReportTest, ARunWhosePlantDiedSaysSoWithTheCountersOfItsLastHeartbeat) {
  const StackConfig config = WriteRunFiles(false);
  const ChannelNames& ch = config.lcm.channels;
  std::ofstream(run_folder_ + "/plant_sim.log") << "plant_sim: 10001 end-stop hits\n";
  {
    lcm::LogFile log(run_folder_ + "/log.lcm", "w");
    ASSERT_TRUE(log.good());
    for (int k = 0; k < kSamples; ++k) {
      const int64_t utime = kUtime0 + 1000 * k;
      const int64_t stamp = kLog0 + 1000 * k;
      state_t s{};
      s.utime = s.sample_utime = utime;
      s.seq = k;
      s.q[2] = 0.4;
      s.qd[0] = k == 300 ? -0.05 : 0.0;
      s.status = state_t::STATUS_VALID | state_t::STATUS_GROUND_TRUTH;
      if (k <= 500) AppendToLog(&log, ch.state_truth, s, stamp);
      s.status = state_t::STATUS_VALID;
      if (k < 1200 || k >= 1210) AppendToLog(&log, ch.state_estimate, s, stamp);
      if (k % 250 == 0) {
        const int64_t seq = k / 250;
        if (k <= 500) {
          const Heartbeat plant{
              "plant_sim", health_t::STATE_OK, {{"endstop_hits", 3 * seq}, {"ticks", k}}, ""};
          AppendToLog(&log, ch.health, HealthMessage(plant, seq, utime), stamp);
        }
        AppendToLog(&log, ch.health, HealthMessage(Named("estimator"), seq, utime), stamp);
        // The controller restarted between its heartbeats of 0.75 s and 1 s.
        AppendToLog(&log, ch.health,
                    HealthMessage(Named("controller"), k < 1000 ? seq : seq - 4, utime), stamp);
      }
    }
  }
  const std::string report = Report();
  for (const std::string& expected : {
           std::string("- plant_sim **stopped reporting** at t = 0.500 s (its last heartbeat, "
                       "state OK), 1.5 s before the log ends, without a STOPPED heartbeat: it "
                       "died, was killed or hung; its log: plant_sim.log"),
           std::string("- the launcher did not finish this run (run.yaml has no wall_time_s)"),
           std::string("the log lacks 10 of "),
           std::string("1 publisher restart(s) during the run"),
           std::string("Plant counters (plant_sim, its last heartbeat, at t = 0.500 s, state OK; "
                       "**stopped reporting**"),
           std::string("endstop_hits 6, ticks 500."),
           std::string("| controller | ok | no | 0 | 0 | 1 (first at t = 1.000 s) |"),
           std::string("## Limits, judged on ground truth (STATE_TRUE)"),
           std::string("Exceeded: none (on ground truth)"),
           std::string("x velocity lower (min -0.05 m/s)"),
       }) {
    EXPECT_NE(report.find(expected), std::string::npos) << "missing: " << expected << "\n"
                                                        << report;
  }
  // The warnings come before the limits.
  EXPECT_LT(report.find("## Warnings"), report.find("## Limits")) << report;
}

}  // namespace
}  // namespace stewart::test
