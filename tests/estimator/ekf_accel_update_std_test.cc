// The dynamics model's acceleration error enters the EKF twice: as the
// velocity's process noise (how fast the legs' corrections reach the
// velocity) and as the predicted acceleration's uncertainty in the
// accelerometer's update (how much the accelerometer tells d, and so d's std,
// the filter's margin). `accel_update_dynamics_std_mps2` sets the second
// apart (docs/estimator.md, "The P-16P legs").
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "ekf_harness.h"
#include "stewart/estimator/ekf.h"

namespace stewart {
namespace {

struct StdRun {
  test::RunStats stats;
  double mean_d_std_n = 0.0;  ///< mean over samples of |d's force-row std|
  Vector6d final_qd = Vector6d::Zero();
  Vector6d final_d = Vector6d::Zero();
};

StdRun RunWithStds(double process_std, double accel_update_std) {
  StackConfig c = test::EstimatorTestConfig();
  c.estimator.dynamics_accel_std_mps2 = process_std;
  c.estimator.accel_update_dynamics_std_mps2 = accel_update_std;
  Ekf ekf = test::MakeEkf(c);
  StdRun run;
  int n = 0;
  test::RunHooks hooks;
  hooks.after = [&](int, const Ekf& e, const test::TruthSample&, const UpdateResult&) {
    if (!e.initialized()) return;
    run.mean_d_std_n += e.estimate().disturbance_std_n.head<3>().norm();
    ++n;
  };
  run.stats = test::RunScenario(c, 3, 6.0, 1.0, &ekf, hooks);
  run.mean_d_std_n /= std::max(n, 1);
  run.final_qd = ekf.estimate().qd;
  run.final_d = ekf.estimate().disturbance_n;
  return run;
}

void Print(const char* label, const StdRun& r) {
  std::printf("[accel update std] %s: d's force std %.4f N (mean), velocity error %.3f mm/s rms\n",
              label, r.mean_d_std_n, 1e3 * r.stats.qd_err.Rms().head<3>().norm());
}

TEST(EkfAccelUpdateStd, UnsetIsTheProcessNoise) {
  const double p = test::EstimatorTestConfig().estimator.dynamics_accel_std_mps2;
  ASSERT_LT(test::EstimatorTestConfig().estimator.accel_update_dynamics_std_mps2, 0.0);
  const StdRun unset = RunWithStds(p, -1.0);
  const StdRun same = RunWithStds(p, p);
  EXPECT_EQ(unset.final_qd, same.final_qd);
  EXPECT_EQ(unset.final_d, same.final_d);
  EXPECT_EQ(unset.mean_d_std_n, same.mean_d_std_n);
}

TEST(EkfAccelUpdateStd, OnlyTheAccelerometersShareWidensTheModelErrorsStd) {
  const double p = test::EstimatorTestConfig().estimator.dynamics_accel_std_mps2;
  const StdRun base = RunWithStds(p, p);
  const StdRun wider_share = RunWithStds(p, 4 * p);
  const StdRun more_process = RunWithStds(4 * p, p);
  Print("shipped", base);
  Print("accelerometer's share x4", wider_share);
  Print("process noise x4, share kept", more_process);
  // The accelerometer is what tells d: a less trusted prediction leaves d
  // less certain, and the filter's margin (disturbance_sigma std) wider.
  EXPECT_GT(wider_share.mean_d_std_n, 1.5 * base.mean_d_std_n);
  // The velocity's process noise alone leaves d's std where it was ...
  EXPECT_NEAR(more_process.mean_d_std_n, base.mean_d_std_n, 0.1 * base.mean_d_std_n);
  // ... while it does act: the velocity follows the legs more loosely.
  EXPECT_GT(more_process.stats.qd_err.Rms().head<3>().norm(),
            1.2 * base.stats.qd_err.Rms().head<3>().norm());
  for (const StdRun* r : {&base, &wider_share, &more_process}) {
    EXPECT_EQ(r->stats.Count(kEventDiverged), 0);
  }
}

}  // namespace
}  // namespace stewart
