// The stack on three hosts: network namespaces of this machine on one bridge
// (tools/netns_lab.sh), the device's host running plant_sim, the control
// host the estimator, controller and safety process, the observer the
// recorder and the monitor, joined by LCM multicast with ttl=1 across the
// bridge, started by tools/launch.sh --hosts. docs/operations.md, "Several
// hosts".
//
// The lab here has names of its own (prefix stt, 10.78.0.0/24, groups
// 239.255.78.0/24), so a developer's lab (stw) may be up beside it. Needs
// root for the namespaces: skipped, saying so, without it. LCM ports
// 8012-8013 on the lab's group.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

const char* const kLabEnv =
    "STEWART_LAB_PREFIX=stt STEWART_LAB_SUBNET=10.78.0 STEWART_LAB_GROUPS=239.255.78.0/24 ";

std::string LabUrl(int port, int ttl = 1) {
  return "udpm://239.255.78.1:" + std::to_string(port) + "?ttl=" + std::to_string(ttl);
}

int Lab(const std::string& args) {
  return test::Shell(std::string(kLabEnv) +
                     test::ShellQuote(std::string(STEWART_SOURCE_DIR) + "/tools/netns_lab.sh") +
                     " " + args + " >/dev/null 2>&1");
}

class HostsLab : public test::WithRunFolder<::testing::Test> {
 protected:
  HostsLab() : WithRunFolder("stewart_hosts") {}
  void SetUp() override {
    WithRunFolder::SetUp();
    if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root; not run";
    if (test::Shell("ip netns add stt-probe >/dev/null 2>&1 && ip netns del stt-probe") != 0) {
      GTEST_SKIP() << "this kernel or container cannot make network namespaces; not run";
    }
    // One lab at a time: ctest runs this file's tests as separate processes.
    lab_lock_fd_ = ::open("/tmp/stewart_hosts_lab.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0600);
    ASSERT_GE(lab_lock_fd_, 0);
    ASSERT_EQ(::flock(lab_lock_fd_, LOCK_EX), 0);
    Lab("down");  // a lab a killed run left behind
    ASSERT_EQ(Lab("up device control observer"), 0) << "tools/netns_lab.sh up failed";
    lab_up_ = true;
    hosts_ = run_folder_ + "/lab.hosts";
    std::ofstream(hosts_) << "host device   ip netns exec stt-device\n"
                             "host control  ip netns exec stt-control\n"
                             "host observer ip netns exec stt-observer\n"
                             "run plant_sim   device\n"
                             "run estimator   control\n"
                             "run controller  control\n"
                             "run safety      control\n"
                             "run logger      observer\n"
                             "run monitor     observer\n";
  }
  void TearDown() override {
    if (lab_up_) {
      EXPECT_EQ(Lab("down"), 0);
    }
    if (lab_lock_fd_ >= 0) ::close(lab_lock_fd_);  // releases the lock
    WithRunFolder::TearDown();
  }

  /// tools/launch.sh on the lab's URL; its output.
  test::LaunchResult Launch(const std::string& args, const std::string& url,
                            const std::string& name) {
    return test::RunLauncherOnUrl("--no-build --hosts " + test::ShellQuote(hosts_) + " " + args,
                                  url, run_folder_ + "/" + name, run_folder_ + "/" + name + ".out");
  }

  std::string hosts_;
  bool lab_up_ = false;
  int lab_lock_fd_ = -1;
};

TEST_F(HostsLab, NetworkCheckSaysWhoHearsWhom) {
  const test::LaunchResult ok = Launch("--check-network", LabUrl(8012), "check");
  const std::string out = test::ReadFile(ok.output_path);
  EXPECT_EQ(ok.exit_code, 0) << out;
  EXPECT_NE(out.find("device hears control"), std::string::npos) << out;
  EXPECT_NE(out.find("every host hears every host"), std::string::npos) << out;

  // ttl=0 across hosts: named, and nobody hears another host.
  const test::LaunchResult ttl0 = Launch("--check-network", LabUrl(8012, 0), "check_ttl0");
  const std::string out_ttl0 = test::ReadFile(ttl0.output_path);
  EXPECT_NE(ttl0.exit_code, 0) << out_ttl0;
  EXPECT_NE(out_ttl0.find("ttl=0"), std::string::npos) << out_ttl0;
}

TEST_F(HostsLab, NetworkCheckNamesAPartition) {
  ASSERT_EQ(Lab("link control down"), 0);
  const test::LaunchResult cut = Launch("--check-network", LabUrl(8012), "check_cut");
  const std::string out = test::ReadFile(cut.output_path);
  EXPECT_NE(cut.exit_code, 0) << out;
  EXPECT_NE(out.find("control hears device: 0 of"), std::string::npos) << out;
  EXPECT_NE(out.find("device hears control: 0 of"), std::string::npos) << out;
  EXPECT_NE(out.find("device hears observer: "), std::string::npos) << out;
  EXPECT_EQ(out.find("device hears observer: 0 of"), std::string::npos) << out;
}

TEST_F(HostsLab, PaperScenarioAcrossThreeHosts) {
  constexpr double kDurationS = 12.0;
  const test::LaunchResult run =
      Launch("--duration " + std::to_string(kDurationS) + " --no-report", LabUrl(8013), "paper");
  ASSERT_EQ(run.exit_code, 0) << test::LaunchFailure(run);
  const std::string folder = run_folder_ + "/paper";
  EXPECT_NE(test::ReadFile(folder + "/run.yaml").find("hosts: "), std::string::npos);
  const StackConfig config = LoadStackConfig(folder + "/config.yaml");
  const test::RecordedRun recorded = test::ReadRecordedRun(folder + "/log.lcm", config);
  ASSERT_NE(recorded.Worst(), nullptr) << "nothing recorded on the observer";
  std::printf("[hosts] %s\n", test::Describe(recorded).c_str());
  EXPECT_GE(static_cast<double>(recorded.truth_samples),
            0.95 * kDurationS * config.sensors.rate_hz);
  test::ExpectWithinLimits(recorded);
  EXPECT_GT(recorded.max_x, 0.05) << "the platform did not move";
}

}  // namespace
}  // namespace stewart
