// tools/launch.sh stops every process it started on every exit path. Piped
// into `head`, it used to die of SIGPIPE at its next line of output and
// leave the logger, safety, controller, estimator and monitor running.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "stewart/node/lcm_handle.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

constexpr int kPort = 7898;  // this folder's private ports: 7820-7829, 7898

// Matches the launched processes' command lines (their --lcm-url), not this
// test's own shell, whose command line holds the pattern with brackets.
const char kLaunchedProcesses[] = "pgrep -f '239[.]255[.]76[.]67:789[8]' >/dev/null";

TEST(LaunchExit, PipedIntoHeadLeavesNoProcessBehind) {
  ASSERT_NE(Shell(kLaunchedProcesses), 0) << "processes of an earlier run are still up";
  const std::string run = ::testing::TempDir() + "launch_exit_run";
  const std::string head = ::testing::TempDir() + "launch_exit_head.txt";
  const std::string launch = "tools/launch.sh --no-build --no-report --duration 30 --out " +
                             ShellQuote(run) + " --lcm-url " + ShellQuote(PrivateLcmUrl(kPort)) +
                             " | head -3 >" + ShellQuote(head);
  const int code = Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) +
                         " && STEWART_BUILD_DIR=" + ShellQuote(STEWART_BUILD_DIR) + " flock " +
                         ShellQuote(std::string(STEWART_BUILD_DIR) + "/stack_launch.lock") +
                         " timeout -k 10 60 bash -c " + ShellQuote(launch));
  EXPECT_NE(code, 124) << "the pipeline did not end: launch.sh outlived its reader";
  // It did start the stack: its banner reached head, and its processes logged.
  EXPECT_NE(ReadFile(head).find("== Stewart stack"), std::string::npos) << ReadFile(head);
  EXPECT_FALSE(ReadFile(run + "/safety.log").empty() && ReadFile(run + "/estimator.log").empty())
      << "no process of the stack was started";
  // stop_all gives the processes up to 3 s before SIGKILL.
  bool gone = false;
  for (int i = 0; i < 50 && !gone; ++i) {
    gone = Shell(kLaunchedProcesses) != 0;
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(gone) << "processes started by tools/launch.sh are still running";
  if (!gone) Shell("pkill -KILL -f '239[.]255[.]76[.]67:789[8]'");
}

}  // namespace
}  // namespace stewart::test
