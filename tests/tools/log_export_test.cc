// A log written with lcm::LogFile comes out as one CSV per channel, with
// every message a row and the values intact; --check says which messages
// the log lacks and which publisher restarted, per stream.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/lcm_messages.h"

namespace stewart {
namespace {

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(LogExport, OneCsvPerChannel) {
  const std::string dir = ::testing::TempDir() + "log_export_test";
  const std::string log_path = dir + ".lcm";
  {
    lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    for (int k = 0; k < 5; ++k) {
      state_t s{};
      s.utime = 1000 * k;
      s.seq = k;
      s.sample_utime = 1000 * k;
      s.q[2] = 0.4 + 0.001 * k;
      test::AppendToLog(&log, "T_STATE", s, 50 + k);
      force_command_t f{};
      f.utime = 1000 * k;
      f.seq = k;
      f.sample_utime = 1000 * k;
      f.force_n[0] = 1.5 * k;
      f.flags = k % 2;
      test::AppendToLog(&log, "T_CMD", f, 60 + k);
    }
    safety_diagnostics_t d{};
    d.utime = d.sample_utime = 7000;
    test::SetGroups({{"x_upper", "leg0_max"}, {0.1, 0.2}, {0.1, 0.2}, {0.75, 0.25}, {0.0, 0.0}},
                    {{"zd_upper"}, {0.01}, {0.02}, {1.0}, {0.5}}, &d);
    test::AppendToLog(&log, "T_DIAG", d, 70);
    lcm::LogEvent junk{};
    uint8_t bytes[4] = {1, 2, 3, 4};
    junk.channel = "T_OTHER";
    junk.datalen = 4;
    junk.data = bytes;
    ASSERT_EQ(log.writeEvent(&junk), 0);
  }
  const std::string cmd = std::string(LOG_EXPORT_PATH) + " " + log_path + " --out " + dir;
  ASSERT_EQ(std::system(cmd.c_str()), 0);

  const auto state = Lines(dir + "/T_STATE.csv");
  ASSERT_EQ(state.size(), 6u);
  EXPECT_EQ(state[0].rfind("log_utime_us,utime_us,seq,sample_utime_us,q_x_m,q_y_m,q_z_m", 0), 0u)
      << state[0];
  EXPECT_EQ(state[3].rfind("52,2000,2,2000,0,0,0.40200000000000002", 0), 0u) << state[3];
  const auto cmd_rows = Lines(dir + "/T_CMD.csv");
  ASSERT_EQ(cmd_rows.size(), 6u);
  EXPECT_EQ(cmd_rows[5], "64,4000,4,4000,6,0,0,0,0,0,0");
  // Diagnostics: the barrier weights by index, and which barrier each index is.
  const auto diag = Lines(dir + "/T_DIAG.csv");
  ASSERT_EQ(diag.size(), 2u);
  std::vector<std::string> header, row;
  for (const auto& [line, out] : {std::pair{diag[0], &header}, std::pair{diag[1], &row}}) {
    std::stringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) out->push_back(cell);
  }
  ASSERT_EQ(header.size(), row.size());
  auto value = [&](const std::string& column) {
    for (size_t i = 0; i < header.size(); ++i) {
      if (header[i] == column) return row[i];
    }
    return std::string("missing");
  };
  EXPECT_EQ(value("w_position0_"), "0.75");
  EXPECT_EQ(value("w_position1_"), "0.25");
  EXPECT_EQ(value("w_velocity0_"), "1");
  EXPECT_EQ(value("mu_velocity0_"), "0.5");  // variant uncomposed's own multipliers
  EXPECT_EQ(value("mu_position1_"), "0");
  EXPECT_EQ(value("h_position1_"), "0.20000000000000001");
  EXPECT_EQ(value("w_position23_"), "0");  // every column a config can have
  const auto barriers = Lines(dir + "/T_DIAG.barriers.csv");
  const std::vector<std::string> expected = {"group,index,name", "position,0,x_upper",
                                             "position,1,leg0_max", "velocity,0,zd_upper"};
  EXPECT_EQ(barriers, expected);
  std::ifstream other(dir + "/T_OTHER.csv");
  EXPECT_FALSE(other.good()) << "unknown types must be skipped, not exported";
}

/// stdout of `command` and its exit code.
std::string RunCommand(const std::string& command, int* code) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = pclose(pipe);
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

/// 100 states, of which the log lacks seq 40-49 and 70; heartbeats of two
/// processes on one channel, one of which restarts after its seq 4.
std::string WriteIncompleteLog(const std::string& log_path) {
  lcm::LogFile log(log_path, "w");
  EXPECT_TRUE(log.good());
  for (int k = 0; k < 100; ++k) {
    const int64_t timestamp = 1'000'000 + 1000 * k;
    if (k % 10 == 0) {
      health_t a{};
      a.name = "alpha";
      a.utime = 1000 * k;
      a.seq = k / 10;
      test::AppendToLog(&log, "T_HEALTH", a, timestamp);
      health_t b{};
      b.name = "beta";
      b.utime = 1000 * k;
      b.seq = k / 10 < 5 ? k / 10 : k / 10 - 5;  // restarted at k = 50
      test::AppendToLog(&log, "T_HEALTH", b, timestamp);
    }
    if ((k >= 40 && k < 50) || k == 70) continue;
    state_t s{};
    s.utime = s.sample_utime = 1000 * k;
    s.seq = k;
    test::AppendToLog(&log, "T_STATE", s, timestamp);
  }
  return log_path;
}

TEST(LogExport, CheckCountsTheMissingMessagesAndRestartsPerStream) {
  const std::string dir = ::testing::TempDir() + "log_export_check";
  const std::string log_path = WriteIncompleteLog(dir + ".lcm");
  const std::string json_path = dir + ".json";
  int code = -1;
  const std::string out = RunCommand(std::string(LOG_EXPORT_PATH) + " " + log_path +
                                         " --check --continuity-json " + json_path + " 2>&1",
                                     &code);
  ASSERT_EQ(code, 0) << out;
  EXPECT_NE(out.find("log: WARNING: 11 of 120 published messages are missing from the log "
                     "(9.2 %, in 2 gaps); WARNING: 1 publisher restart(s)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("T_STATE: 89 recorded, 11 missing (11.0 %) in 2 gap(s); first gap at "
                     "utime 50000 us (log +0.050 s, seq 39 -> 50)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("T_HEALTH[beta]: 10 recorded, restarted 1 time(s); first restart at utime "
                     "50000 us"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("T_HEALTH[alpha]"), std::string::npos) << out;
  EXPECT_FALSE(std::ifstream(dir + "_csv/T_STATE.csv").good()) << "--check writes no CSV";

  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("missing"), 11);
  EXPECT_EQ(j.at("restarts"), 1);
  EXPECT_EQ(j.at("streams").at("T_STATE").at("gaps"), 2);
  EXPECT_EQ(j.at("streams").at("T_HEALTH[alpha]").at("missing"), 0);
  ASSERT_EQ(j.at("events").size(), 3u);
  EXPECT_EQ(j.at("events")[0].at("kind"), "restart");
  EXPECT_EQ(j.at("events")[0].at("stream"), "T_HEALTH[beta]");
  EXPECT_EQ(j.at("events")[0].at("previous_seq"), 4);
  EXPECT_EQ(j.at("events")[2].at("kind"), "gap");
  EXPECT_EQ(j.at("events")[2].at("utime_us"), 71000);
}

TEST(LogExport, ACompleteLogSaysSo) {
  const std::string dir = ::testing::TempDir() + "log_export_complete";
  {
    lcm::LogFile log(dir + ".lcm", "w");
    for (int k = 0; k < 10; ++k) {
      state_t s{};
      s.seq = k;
      test::AppendToLog(&log, "T_STATE", s, 100 + k);
    }
  }
  int code = -1;
  const std::string out =
      RunCommand(std::string(LOG_EXPORT_PATH) + " " + dir + ".lcm --out " + dir + " 2>&1", &code);
  ASSERT_EQ(code, 0) << out;
  EXPECT_NE(out.find("log: complete: 10 numbered messages in 1 streams"), std::string::npos) << out;
  EXPECT_EQ(Lines(dir + "/T_STATE.csv").size(), 11u);
}

}  // namespace
}  // namespace stewart
