#include "stewart/test_support/stack_launch.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "stewart/node/lcm_handle.h"

namespace stewart::test {

LauncherLock::LauncherLock()
    // Close-on-exec: a child that outlived its test must not hold the lock.
    : fd_(open(STEWART_BUILD_DIR "/stack_launch.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
  if (fd_ >= 0) flock(fd_, LOCK_EX);
}

LauncherLock::~LauncherLock() {
  if (fd_ >= 0) close(fd_);  // releases the lock
}

std::string WriteAutoArmOverlay(const std::string& folder, const std::string& extra_yaml) {
  const std::string path = folder + "/stack_overlay.yaml";
  std::ofstream(path) << "supervisor:\n  auto_arm: true\n" << extra_yaml;
  return path;
}

std::string WriteMismatchedTruth(const std::string& folder) {
  const std::string path = folder + "/truth.yaml";
  std::ofstream(path) << R"(# The plant differs from config/platform.yaml (the stack's model).
platform:
  mass_kg: 0.80
  payload: {mass_kg: 0.15, position_m: [0.03, -0.02, 0.02]}
  base_joint_radius_offsets_m: [0.0005, 0, -0.0005, 0, 0.0005, 0]
  platform_joint_radius_offsets_m: [0, -0.0005, 0, 0.0005, 0, -0.0005]
legs: {cylinder_mass_kg: 0.18, rod_mass_kg: 0.05}
actuators:
  viscous_friction_nspm: 3.0
  coulomb_friction_n: 0.1
  force_gain: [1.05, 0.95, 1.0, 1.0, 1.03, 0.97]
disturbance:
  constant_force_n: [0.3, -0.2, 0.2]
)";
  return path;
}

StackWithoutPlant::StackWithoutPlant(
    const StackPrograms& programs, const std::string& url, const std::string& log_path,
    const std::function<std::vector<std::string>(std::vector<std::string>)>& with)
    : logger({programs.logger, "--lcm-url=" + url + "&recv_buf_size=4194304", "-f", log_path}),
      safety(with({programs.safety})),
      controller(with({programs.controller, "--scenario", "paper"})),
      estimator(with({programs.estimator})) {}

std::vector<std::string> WithStackFlags(std::vector<std::string> argv, const std::string& url,
                                        const std::string& overlay) {
  for (const std::string& flag : {std::string("--lcm-url"), url, std::string("--overlay"), overlay,
                                  std::string("--log-level"), std::string("warn")}) {
    argv.push_back(flag);
  }
  return argv;
}

std::string ShellQuote(const std::string& s) {
  std::string quoted = "'";
  for (char ch : s) {
    if (ch == '\'') {
      quoted += "'\\''";
    } else {
      quoted += ch;
    }
  }
  return quoted + "'";
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string FormatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

int Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  if (status == -1) return -1;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

LaunchResult RunLauncher(const std::string& args, int lcm_port, const std::string& run_dir,
                         const std::string& output_path) {
  return RunLauncherOnUrl(args, PrivateLcmUrl(lcm_port), run_dir, output_path);
}

LaunchResult RunLauncherOnUrl(const std::string& args, const std::string& url,
                              const std::string& run_dir, const std::string& output_path) {
  LaunchResult launch;
  launch.output_path = output_path;
  const auto start = std::chrono::steady_clock::now();
  launch.exit_code =
      Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) +
            " && STEWART_BUILD_DIR=" + ShellQuote(STEWART_BUILD_DIR) + " flock " +
            ShellQuote(std::string(STEWART_BUILD_DIR) + "/stack_launch.lock") + " timeout -k 30 " +
            std::to_string(kLaunchTimeoutS) + " tools/launch.sh " + args + " --out " +
            ShellQuote(run_dir) + " --lcm-url " + ShellQuote(url) + " >" + ShellQuote(output_path) +
            " 2>&1");
  launch.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return launch;
}

std::string LaunchFailure(const LaunchResult& launch) {
  std::ostringstream text;
  text << "tools/launch.sh failed after " << launch.wall_s << " s (124: killed by the "
       << kLaunchTimeoutS << " s guard); its output:\n"
       << ReadFile(launch.output_path);
  return text.str();
}

}  // namespace stewart::test
