// Starting the LCM stack from a test: tools/launch.sh on the build folder the
// test was built in, on a private LCM URL, in a temporary run folder that is
// kept when the test fails.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "stewart/test_support/child_process.h"

namespace stewart::test {

/// Guard on each launcher run: SIGTERM after this, SIGKILL 30 s later.
constexpr int kLaunchTimeoutS = 300;

/// `s` as one single-quoted shell word.
std::string ShellQuote(const std::string& s);

/// The whole file; empty if it cannot be read.
std::string ReadFile(const std::string& path);

/// `value` as printf's %g writes it.
std::string FormatNumber(double value);

/// Exit code of a shell command (128 + signal if killed, -1 if it could not run).
int Shell(const std::string& command);

/// How a launcher run ended.
struct LaunchResult {
  int exit_code = -1;       ///< Shell()'s code (124: killed by the kLaunchTimeoutS guard)
  double wall_s = 0.0;      ///< how long the launcher ran
  std::string output_path;  ///< its stdout and stderr
};

/// Runs `tools/launch.sh <args> --out <run_dir> --lcm-url <private URL on lcm_port>`
/// from the source folder on this build folder; its output goes to
/// `output_path`. `args` must hold --no-build: ctest must not rebuild under
/// itself. One launcher at a time per build folder (flock on
/// <build>/stack_launch.lock), so parallel ctest runs do not share 2 cores
/// four processes each; kLaunchTimeoutS guards it.
LaunchResult RunLauncher(const std::string& args, int lcm_port, const std::string& run_dir,
                         const std::string& output_path);

/// The same on `url` (a URL of the test's own, e.g. with ttl=1 on a
/// network-namespace lab).
LaunchResult RunLauncherOnUrl(const std::string& args, const std::string& url,
                              const std::string& run_dir, const std::string& output_path);

/// Holds the launcher lock of this build folder (<build>/stack_launch.lock)
/// while a test runs a stack of its own, so that no two stacks share the 2
/// cores (RunLauncher takes the same lock).
class LauncherLock {
 public:
  LauncherLock();
  ~LauncherLock();
  LauncherLock(const LauncherLock&) = delete;
  LauncherLock& operator=(const LauncherLock&) = delete;

 private:
  int fd_;
};

/// Handles `receiver`'s messages (an LcmReceiver) until `done()` or
/// `timeout_s` has passed: whether `done()`.
template <typename Receiver, typename Done>
bool PumpUntil(Receiver* receiver, Done done, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    receiver->HandleTimeout(1);
  }
  return true;
}

/// Writes `folder`/stack_overlay.yaml: the supervisor armed at start-up, as
/// tools/launch.sh does in simulation, plus `extra_yaml` (other sections);
/// returns its path.
std::string WriteAutoArmOverlay(const std::string& folder, const std::string& extra_yaml = "");

/// Writes `folder`/truth.yaml, the physics of a plant that is not the model
/// (29 % heavier, a 0.15 kg payload off centre, heavier legs, joints 0.5 mm
/// off, 1.5x friction plus Coulomb friction, force gains +-5 %, a constant
/// push) yet inside what the stack holds its limits against: the plant the
/// fault tests give plant_sim and hw_emulator (`--truth`); returns its path.
std::string WriteMismatchedTruth(const std::string& folder);

/// `argv` plus the flags every stack process of a test takes: the private
/// `url`, the `overlay`, warnings only.
std::vector<std::string> WithStackFlags(std::vector<std::string> argv, const std::string& url,
                                        const std::string& overlay);

/// Paths of the programs a lockstep test starts (the test's TARGET_FILEs).
struct StackPrograms {
  std::string logger, safety, controller, estimator;
};

/// The logger and the stack's processes but the plant, as the lockstep tests
/// start them: the logger recording `log_path` on `url`, the controller on
/// the paper scenario; `with` adds each process's flags (WithStackFlags, a
/// CPU pin). The plant comes last, once their heartbeats are in.
struct StackWithoutPlant {
  StackWithoutPlant(const StackPrograms& programs, const std::string& url,
                    const std::string& log_path,
                    const std::function<std::vector<std::string>(std::vector<std::string>)>& with);
  bool started() const {
    return logger.started() && safety.started() && controller.started() && estimator.started();
  }
  ChildProcess logger, safety, controller, estimator;
};

/// Why a launch failed, for the test's message: the exit code's meaning, the
/// wall time and the launcher's whole output.
std::string LaunchFailure(const LaunchResult& launch);

/// A test fixture with a fresh folder /tmp/<prefix>_XXXXXX (run_folder_) for
/// the run: removed after a pass, kept and its path printed after a failure.
template <class Base>
class WithRunFolder : public Base {
 protected:
  explicit WithRunFolder(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    std::string pattern = "/tmp/" + prefix_ + "_XXXXXX";
    ASSERT_NE(mkdtemp(pattern.data()), nullptr) << std::strerror(errno);
    run_folder_ = pattern;
  }
  void TearDown() override {
    if (run_folder_.empty()) return;
    if (::testing::Test::HasFailure()) {
      std::printf("run folder kept: %s\n", run_folder_.c_str());
      return;
    }
    std::error_code ignored;
    std::filesystem::remove_all(run_folder_, ignored);
  }

  std::string run_folder_;

 private:
  std::string prefix_;
};

}  // namespace stewart::test
