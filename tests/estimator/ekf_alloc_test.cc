// No heap allocation per EKF update: operator new is counted while updates
// run (its own binary, so the replacement affects nothing else).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "ekf_harness.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace stewart::test {
namespace {

TEST(EkfAllocation, UpdatesDoNotAllocate) {
  for (auto model : {EstimatorProcessModel::kConstantVelocity, EstimatorProcessModel::kDynamics}) {
    StackConfig c = EstimatorTestConfig();
    c.estimator.process_model = model;
    Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
    ScenarioTruth truth(c, 12);
    std::vector<TruthSample> samples;
    for (int k = 0; k < 2000; ++k) samples.push_back(truth.Next());
    ASSERT_TRUE(ekf.Update(samples[0].sensors).has_estimate);
    const long before = g_allocations.load();
    for (size_t k = 1; k < samples.size(); ++k) {
      ekf.SetForceCommand(samples[k - 1].utime, samples[k - 1].force_n);
      ekf.Update(samples[k].sensors);
      const Estimate e = ekf.estimate();
      ASSERT_TRUE(e.q.allFinite());
    }
    EXPECT_EQ(g_allocations.load(), before);
  }
}

}  // namespace
}  // namespace stewart::test
