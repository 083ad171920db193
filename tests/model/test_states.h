#pragma once
// Random states inside the workspace, shared by the model tests.
#include <random>

#include "stewart/config/stack_config.h"
#include "stewart/model/types.h"

namespace stewart::test {

const StackConfig& DefaultConfig();

/// A pose around home with every leg inside the stroke.
Vector6d RandomPose(std::mt19937* rng);
Vector6d RandomVelocity(std::mt19937* rng);

/// Calls `f(q, rng)` for `n` random poses q drawn from a generator seeded
/// with `seed`; `f` may draw more from `rng` after each pose.
template <typename F>
void ForRandomPoses(unsigned seed, int n, F f) {
  std::mt19937 rng(seed);
  for (int k = 0; k < n; ++k) {
    const Vector6d q = RandomPose(&rng);
    f(q, &rng);
  }
}

}  // namespace stewart::test
