// A message of the lockstep loop lost on its way: the plant resends its
// sample after 0.2 s, and every node that answered that sample already
// answers it again with the same output (common/resend_answer.h), so the run
// completes instead of stalling until plant_sim's lockstep timeout.
//
// The real processes (plant_sim --mode lockstep, estimator, controller,
// safety, stewart_logger) on a private URL; the loss is a node that does not
// publish one output (--test-lose-seq: the datagram never reaches the wire,
// as when UDP drops it), deterministic where a test on the bus could not
// remove a multicast datagram. Each run is compared with one without the
// loss: the same seed, so the ground truth must be byte-identical (the
// resend changes nothing the plant does, only when).
//
// LCM ports 8030-8032 (this file owns 8030-8039). It holds the launcher lock
// of the build folder, as the launched-stack tests do.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kFirstPort = 8030;
/// 1000 ticks at 1 kHz; the loss at seq 300 (the stack armed by then).
constexpr double kDurationS = 1.0;
constexpr int64_t kLostSeq = 300;

struct LockstepResult {
  int plant_exit = -1;
  double wall_s = 0.0;
  std::vector<std::vector<uint8_t>> truth;  ///< encoded ground truth, log order
  std::map<std::string, health_t> health;   ///< each process's last heartbeat
};

/// One lockstep run on `port`; `lose` is "" or the process ("estimator",
/// "safety") that loses its output kLostSeq.
LockstepResult LockstepRun(const std::string& folder, int port, const std::string& lose) {
  LockstepResult run;
  const std::string log_path = folder + "/log_" + std::to_string(port) + ".lcm";
  // A short lockstep timeout: without the resend rule the loss ends the run
  // there (exit 3) instead of 5 s later.
  const std::string overlay =
      test::WriteAutoArmOverlay(folder, "plant_sim:\n  lockstep_timeout_s: 2.0\n");
  const StackConfig config = LoadStackConfig(DefaultConfigPath(), {overlay});
  const std::string url = PrivateLcmUrl(port);
  const auto with = [&](std::vector<std::string> argv) {
    const bool loses = (lose == "estimator" && argv[0] == ESTIMATOR_PATH) ||
                       (lose == "safety" && argv[0] == SAFETY_PATH);
    if (loses) {
      argv.push_back("--test-lose-seq");
      argv.push_back(std::to_string(kLostSeq));
    }
    return test::WithStackFlags(std::move(argv), url, overlay);
  };
  LcmReceiver receiver(url);
  struct Health {
    void On(const lcm::ReceiveBuffer*, const std::string&, const health_t* m) {
      last[m->name] = *m;
    }
    std::map<std::string, health_t> last;
  } health;
  receiver.Subscribe(config.lcm.channels.health, &Health::On, &health);
  test::StackWithoutPlant stack({LOGGER_PATH, SAFETY_PATH, CONTROLLER_PATH, ESTIMATOR_PATH}, url,
                                log_path, with);
  EXPECT_TRUE(stack.started());
  EXPECT_TRUE(test::PumpUntil(
      &receiver,
      [&] {
        return health.last.count("safety") && health.last.count("controller") &&
               health.last.count("estimator");
      },
      15.0))
      << "the stack did not come up";
  const auto start = std::chrono::steady_clock::now();
  test::ChildProcess plant(
      with({PLANT_SIM_PATH, "--mode", "lockstep", "--duration", std::to_string(kDurationS)}));
  EXPECT_TRUE(plant.started());
  EXPECT_TRUE(test::PumpUntil(
      &receiver, [&] { return !plant.running(); }, 30.0))
      << "plant_sim did not end";
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.plant_exit = plant.exit_code();
  // The processes' last heartbeats (2 Hz) with the run's counters.
  test::PumpUntil(
      &receiver, [] { return false; }, 0.7);
  run.health = health.last;
  stack.logger.Stop(SIGTERM);
  for (test::ChildProcess* p : {&stack.safety, &stack.controller, &stack.estimator}) {
    EXPECT_TRUE(p->running()) << "a stack process died";
    p->Stop(SIGTERM);
  }
  lcm::LogFile log(log_path, "r");
  EXPECT_TRUE(log.good());
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != config.lcm.channels.state_truth) continue;
    const auto* data = static_cast<const uint8_t*>(event->data);
    run.truth.emplace_back(data, data + event->datalen);
  }
  std::printf(
      "[lockstep resend] lose %s: plant_sim exit %d after %.2f s, %zu truth samples, "
      "lockstep_resends %lld, resends_answered estimator %lld controller %lld safety %lld, "
      "estimator samples_waited_for_answer %lld answer_not_heard %lld\n",
      lose.empty() ? "nothing" : lose.c_str(), run.plant_exit, run.wall_s, run.truth.size(),
      static_cast<long long>(test::HealthCounter(run.health["plant_sim"], "lockstep_resends")),
      static_cast<long long>(test::HealthCounter(run.health["estimator"], "resends_answered")),
      static_cast<long long>(test::HealthCounter(run.health["controller"], "resends_answered")),
      static_cast<long long>(test::HealthCounter(run.health["safety"], "resends_answered")),
      static_cast<long long>(
          test::HealthCounter(run.health["estimator"], "samples_waited_for_answer")),
      static_cast<long long>(test::HealthCounter(run.health["estimator"], "answer_not_heard")));
  std::fflush(stdout);
  // A sample that overtook its answer waited for it (EstimatorProcess::
  // OnSensor): the answer had reached the plant, so it reaches every socket.
  EXPECT_EQ(test::HealthCounter(run.health["estimator"], "answer_not_heard"), 0);
  return run;
}

class LockstepResend : public test::WithRunFolder<::testing::Test> {
 protected:
  LockstepResend() : WithRunFolder("stewart_lockstep_resend") {}
};

TEST_F(LockstepResend, ALostMessageIsAnsweredAgainAndTheRunIsTheSameAsWithoutTheLoss) {
  test::LauncherLock lock;
  LockstepResult reference = LockstepRun(run_folder_, kFirstPort, "");
  ASSERT_EQ(reference.plant_exit, 0);
  const auto ticks = static_cast<size_t>(kDurationS * 1000.0) + 1;
  ASSERT_EQ(reference.truth.size(), ticks);
  EXPECT_EQ(test::HealthCounter(reference.health["plant_sim"], "lockstep_resends"), 0);

  // The estimate of one sample lost (to the controller, the safety process
  // and the logger alike): the plant resends the sample, the estimator
  // answers it again with that estimate, without a second EKF update.
  LockstepResult lost_state = LockstepRun(run_folder_, kFirstPort + 1, "estimator");
  EXPECT_EQ(lost_state.plant_exit, 0) << "the loop stalled on the lost estimate";
  EXPECT_GE(test::HealthCounter(lost_state.health["plant_sim"], "lockstep_resends"), 1);
  EXPECT_GE(test::HealthCounter(lost_state.health["estimator"], "resends_answered"), 1);
  EXPECT_TRUE(lost_state.truth == reference.truth)
      << "the ground truth differs from the run without the loss";

  // The safe command lost (to the plant and the estimator): the plant
  // resends, and the estimator, the controller and the safety process each
  // answer the copy of the input they answered with the same output.
  LockstepResult lost_command = LockstepRun(run_folder_, kFirstPort + 2, "safety");
  EXPECT_EQ(lost_command.plant_exit, 0) << "the loop stalled on the lost command";
  EXPECT_GE(test::HealthCounter(lost_command.health["plant_sim"], "lockstep_resends"), 1);
  for (const char* name : {"estimator", "controller", "safety"}) {
    EXPECT_GE(test::HealthCounter(lost_command.health[name], "resends_answered"), 1) << name;
  }
  EXPECT_TRUE(lost_command.truth == reference.truth)
      << "the ground truth differs from the run without the loss";
}

}  // namespace
}  // namespace stewart
