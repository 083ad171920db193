// tools/launch.sh stops every process it started on every exit path. Piped
// into `head`, it used to die of SIGPIPE at its next line of output and
// leave the logger, safety, controller, estimator and monitor running. And
// tools/report.sh says what is wrong with a folder it cannot report on (it
// exited 105, silently), and reports a run recorded with --log elsewhere.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "stewart/node/lcm_handle.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

// This folder's private ports: 7820-7829, 7898, 7899 (7829: LaunchSpy). The two tests below
// run at the same time under ctest -j and must not share a port: the first
// looks for (and kills) every process on its own.
constexpr int kLaunchExitPort = 7898;
constexpr int kReportShPort = 7899;
constexpr int kSpyPort = 7829;

// Matches the launched processes' command lines (their --lcm-url), not this
// test's own shell, whose command line holds the pattern with brackets.
const char kLaunchedProcesses[] = "pgrep -f '239[.]255[.]76[.]67:789[8]' >/dev/null";

TEST(LaunchExit, PipedIntoHeadLeavesNoProcessBehind) {
  ASSERT_NE(Shell(kLaunchedProcesses), 0) << "processes of an earlier run are still up";
  const std::string run = ::testing::TempDir() + "launch_exit_run";
  const std::string head = ::testing::TempDir() + "launch_exit_head.txt";
  // The reader keeps the banner's first three lines, as `head -3` would, but
  // goes away only at launch.sh's first progress line ("  t = ..."), once
  // every process is up: `head -3` itself raced the start-up (launch.sh died
  // at its next write, before or after starting the stack, by timing).
  const std::string launch = "tools/launch.sh --no-build --no-report --duration 30 --out " +
                             ShellQuote(run) + " --lcm-url " +
                             ShellQuote(PrivateLcmUrl(kLaunchExitPort)) +
                             " | sed -n '1,3p; /^  t = /q' >" + ShellQuote(head);
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

/// `--spy` on a host without a display: lcm-spy (a window) would die at
/// once, its reason only in its own log; the run used to go on without a
/// word. Now the user is told, and the run itself is unaffected.
TEST(LaunchSpy, WithoutADisplayTheRunSaysSoAndGoesOn) {
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display ? display : "";
  ::unsetenv("DISPLAY");
  const std::string run = ::testing::TempDir() + "launch_spy_run";
  Shell("rm -rf " + ShellQuote(run));
  const LaunchResult launch = RunLauncher("--no-build --no-report --duration 1 --spy", kSpyPort,
                                          run, ::testing::TempDir() + "launch_spy.txt");
  if (display) ::setenv("DISPLAY", saved.c_str(), 1);
  ASSERT_EQ(launch.exit_code, 0) << LaunchFailure(launch);
  const std::string out = ReadFile(launch.output_path);
  EXPECT_NE(out.find("--spy needs a display and DISPLAY is not set"), std::string::npos) << out;
  EXPECT_NE(out.find("xvfb-run tools/lcm-spy"), std::string::npos) << out;
}

std::string ReportSh(const std::string& args, int* code) {
  const std::string err = ::testing::TempDir() + "report_sh_err.txt";
  *code = Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) +
                " && STEWART_BUILD_DIR=" + ShellQuote(STEWART_BUILD_DIR) + " tools/report.sh " +
                args + " >/dev/null 2>" + ShellQuote(err));
  return ReadFile(err);
}

TEST(ReportSh, AFolderItCannotReportOnGetsOneClearError) {
  int code = 0;
  std::string err = ReportSh("/nonexistent/run", &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("is not a run folder"), std::string::npos) << err;
  const std::string empty = ::testing::TempDir() + "report_empty_run";
  ASSERT_EQ(
      Shell("mkdir -p " + ShellQuote(empty) + " && : > " + ShellQuote(empty + "/config.yaml")), 0);
  err = ReportSh(ShellQuote(empty), &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("no log"), std::string::npos) << err;
}

TEST(ReportSh, ARunRecordedElsewhereWithLogIsReported) {
  const std::string run = ::testing::TempDir() + "launch_log_elsewhere_run";
  const std::string log = ::testing::TempDir() + "launch_log_elsewhere.lcm";
  Shell("rm -rf " + ShellQuote(run) + " " + ShellQuote(log));
  const LaunchResult launch =
      RunLauncher("--no-build --duration 2 --log " + ShellQuote(log), kReportShPort, run,
                  ::testing::TempDir() + "launch_log.txt");
  ASSERT_EQ(launch.exit_code, 0) << LaunchFailure(launch);
  EXPECT_FALSE(ReadFile(log).empty()) << "nothing recorded to " << log;
  EXPECT_NE(ReadFile(run + "/report.md").find("## Limits"), std::string::npos)
      << "no report for the run recorded with --log";
}

}  // namespace
}  // namespace stewart::test
