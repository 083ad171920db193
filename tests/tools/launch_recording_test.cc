// tools/launch.sh says at the end of a recorded run whether the log holds
// every message the stack published: with --lcm-logger (LCM's own logger,
// which drops bursts when descheduled) a run used to lose a fifth of its
// messages without a word. The test counts the gaps in each stream's seq
// itself and holds the launcher's line to that count.
#include <gtest/gtest.h>

#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>

#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

constexpr int kPort = 8120;  // this folder's private LCM ports: 8120-8129

struct Counts {
  long recorded = 0;
  long missing = 0;
};

/// Per stream (a channel; the heartbeats per process), the messages recorded
/// and those whose seq the log skips.
Counts CountLog(const std::string& path) {
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good()) << path;
  std::map<std::string, int64_t> last_seq;
  Counts c;
  auto observe = [&](const std::string& stream, int64_t seq) {
    const auto it = last_seq.find(stream);
    const int64_t expected = it == last_seq.end() ? 0 : it->second + 1;
    if (seq > expected) c.missing += seq - expected;
    last_seq[stream] = seq;
    ++c.recorded;
  };
  auto try_type = [&](const lcm::LogEvent& e, auto msg) {
    int64_t hash = 0;
    std::memcpy(&hash, e.data, sizeof hash);
    hash = static_cast<int64_t>(__builtin_bswap64(static_cast<uint64_t>(hash)));
    if (hash != decltype(msg)::getHash()) return false;
    if (msg.decode(e.data, 0, e.datalen) != e.datalen) return false;
    std::string stream = e.channel;
    if constexpr (std::is_same_v<decltype(msg), health_t>) stream += "[" + msg.name + "]";
    observe(stream, msg.seq);
    return true;
  };
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->datalen < 8) continue;
    try_type(*e, sensor_t{}) || try_type(*e, state_t{}) || try_type(*e, setpoint_t{}) ||
        try_type(*e, force_command_t{}) || try_type(*e, safety_diagnostics_t{}) ||
        try_type(*e, health_t{}) || try_type(*e, supervisor_state_t{});
  }
  return c;
}

class LaunchRecording : public WithRunFolder<::testing::Test> {
 protected:
  LaunchRecording() : WithRunFolder("stewart_launch_recording") {}
};

TEST_F(LaunchRecording, WithLcmLoggerTheRunEndsSayingWhatTheLogLacks) {
  const LaunchResult launch = RunLauncher("--no-build --no-report --lcm-logger --duration 4", kPort,
                                          run_folder_, run_folder_ + "/launch.txt");
  ASSERT_EQ(launch.exit_code, 0) << LaunchFailure(launch);
  const Counts c = CountLog(run_folder_ + "/log.lcm");
  ASSERT_GT(c.recorded, 4000) << "the run recorded almost nothing";
  const std::string output = ReadFile(launch.output_path);
  if (c.missing > 0) {
    EXPECT_NE(output.find("launch: log: WARNING: " + std::to_string(c.missing) + " of " +
                          std::to_string(c.recorded + c.missing) +
                          " published messages are missing from the log"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("recorded with --lcm-logger, which drops bursts"), std::string::npos)
        << output;
  } else {
    EXPECT_NE(output.find("log: complete: " + std::to_string(c.recorded) + " numbered messages"),
              std::string::npos)
        << output;
  }
  std::printf("lcm-logger: %ld of %ld messages missing\n", c.missing, c.recorded + c.missing);
}

}  // namespace
}  // namespace stewart::test
