// hw_emulator --truth: the emulated device runs a truth file's physics; a bad
// file stops it before it opens a socket, exit 2, naming the key.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace {

std::string RunEmulator(const std::string& truth_yaml, int* exit_code) {
  const std::string truth = testing::TempDir() + "/emulator_truth.yaml";
  const std::string log = testing::TempDir() + "/emulator_truth.log";
  std::ofstream(truth) << truth_yaml;
  // --duration-s 0.05 on private ports: a good truth runs briefly and exits 0.
  const std::string command = std::string(HW_EMULATOR_EXE) + " --truth " + truth +
                              " --device-port 17628 --host-port 17629 --duration-s 0.05 > " + log +
                              " 2>&1";
  const int status = std::system(command.c_str());
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(truth.c_str());
  std::remove(log.c_str());
  return text.str();
}

TEST(EmulatorTruthCli, GoodTruthRunsAndBadTruthExitsTwoNamingTheKey) {
  int code = -1;
  const std::string good = RunEmulator("platform: {payload: {mass_kg: 0.2}}\n", &code);
  EXPECT_EQ(code, 0) << good;
  const std::string bad = RunEmulator("actuators: {force_gain: [1, 1, 1]}\n", &code);
  EXPECT_EQ(code, 2) << bad;
  EXPECT_NE(bad.find("truth.actuators.force_gain"), std::string::npos) << bad;
}

}  // namespace
