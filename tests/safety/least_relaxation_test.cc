#include "stewart/safety/least_relaxation.h"

#include <gtest/gtest.h>

#include <functional>
#include <vector>

namespace stewart::safety::test {
namespace {

// A threshold relaxation: the tries are solved from `threshold` up.
struct Threshold {
  double threshold;
  std::vector<double> tries;
  bool operator()(double r) {
    tries.push_back(r);
    return r >= threshold;
  }
};

TEST(LeastRelaxation, FindsTheThresholdWithinTheToleranceFromAbove) {
  for (const double threshold : {1e-6, 0.1, 0.37, 0.5, 0.9, 0.999}) {
    Threshold solves{threshold, {}};
    const std::optional<double> least = LeastRelaxation(2.0, std::ref(solves));
    ASSERT_TRUE(least.has_value()) << threshold;
    // Never below the threshold (the answer it keeps solved), never more
    // than the tolerance above it.
    EXPECT_GE(*least, threshold);
    EXPECT_LE(*least - threshold, kRelaxationRelTol * 2.0) << threshold;
    EXPECT_LE(static_cast<int>(solves.tries.size()), kMaxRelaxationSteps);
    for (const double r : solves.tries) {
      EXPECT_GT(r, 0.0);
      EXPECT_LT(r, 2.0);
    }
  }
}

TEST(LeastRelaxation, NothingBelowTheUpperBoundSolvesGivesNullopt) {
  // Only `upper` itself solves: the caller's answer without the rows stands.
  Threshold solves{1.0, {}};
  EXPECT_FALSE(LeastRelaxation(1.0, std::ref(solves)).has_value());
  EXPECT_FALSE(solves.tries.empty());
}

TEST(LeastRelaxation, AnyRelaxationSolvingStopsNearZero) {
  Threshold solves{0.0, {}};
  const std::optional<double> least = LeastRelaxation(3.0, std::ref(solves));
  ASSERT_TRUE(least.has_value());
  EXPECT_LE(*least, kRelaxationRelTol * 3.0);
}

}  // namespace
}  // namespace stewart::safety::test
