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

}  // namespace stewart::test
