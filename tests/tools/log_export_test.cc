// A log written with lcm::LogFile comes out as one CSV per channel, with
// every message a row and the values intact.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "stewart/force_command_t.hpp"
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

}  // namespace
}  // namespace stewart
