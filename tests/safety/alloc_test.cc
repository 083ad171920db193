// No heap allocation in the filter step: this binary replaces the global
// operator new with a counting one.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "safety_test_support.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace stewart::safety::test {
namespace {

long CountStepAllocations(bool force_limits, bool with_terms,
                          SafetyVariant variant = SafetyVariant::kClosedForm) {
  SafetyConfig config = RichSafetyConfig();
  config.force_limits_enabled = force_limits;
  config.variant = variant;
  SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
  std::mt19937 rng(1);
  std::vector<Vector6d> q, qd, f;
  std::vector<DynamicsTerms> terms;
  for (int i = 0; i < 500; ++i) {
    q.push_back(RandomPoseInLimits(&rng));
    qd.push_back(RandomVelocity(&rng));
    terms.push_back(EvaluateDynamics(DefaultConfig().platform, q.back(), qd.back()));
    f.push_back(RandomNominalForce(terms.back(), &rng));
  }
  f[0](0) = NAN;  // the fallback path too
  SafetyDiagnostics d;
  const long before = g_allocations.load();
  for (int i = 0; i < 500; ++i) {
    if (with_terms) {
      filter.StepWithTerms(terms[static_cast<size_t>(i)], q[static_cast<size_t>(i)],
                           qd[static_cast<size_t>(i)], f[static_cast<size_t>(i)], &d);
    } else {
      filter.Step(q[static_cast<size_t>(i)], qd[static_cast<size_t>(i)], f[static_cast<size_t>(i)],
                  &d);
    }
  }
  return g_allocations.load() - before;
}

// Through a volatile pointer the vector escapes: the optimiser may not elide
// its allocations (it may elide a new/delete pair nothing observes).
std::vector<int>* volatile g_escaped_vector = nullptr;

TEST(Allocation, CounterWorks) {
  const long before = g_allocations.load();
  g_escaped_vector = new std::vector<int>(10);
  delete g_escaped_vector;
  EXPECT_GE(g_allocations.load() - before, 2);
}

TEST(Allocation, CoreStepDoesNotAllocate) { EXPECT_EQ(CountStepAllocations(false, true), 0); }
TEST(Allocation, FullStepDoesNotAllocate) { EXPECT_EQ(CountStepAllocations(false, false), 0); }
TEST(Allocation, ForceLimitedStepDoesNotAllocate) {
  EXPECT_EQ(CountStepAllocations(true, false), 0);
}
// The un-composed QP (up to 48 rows, fixed-size storage), with and without
// force limits, including its infeasibility fallback.
TEST(Allocation, UncomposedStepDoesNotAllocate) {
  EXPECT_EQ(CountStepAllocations(false, false, SafetyVariant::kUncomposed), 0);
  EXPECT_EQ(CountStepAllocations(true, false, SafetyVariant::kUncomposed), 0);
}

}  // namespace
}  // namespace stewart::safety::test
