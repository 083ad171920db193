#pragma once
// Configs and random states shared by the safety filter tests.
#include <random>

#include "stewart/config/stack_config.h"
#include "stewart/model/dynamics.h"
#include "stewart/safety/safety_filter.h"

namespace stewart::safety::test {

const StackConfig& DefaultConfig();

/// Every constraint kind at once: lower and upper position limits on
/// x, y, z, phi; leg strokes; lower and upper velocity limits on x, y, z, psi.
SafetyConfig RichSafetyConfig();

/// Pose inside the rich config's position limits and the leg strokes.
Vector6d RandomPoseInLimits(std::mt19937* rng);
/// Velocity of log-uniform size (1e-4 .. 3e-2 m/s, rad/s scaled).
Vector6d RandomVelocity(std::mt19937* rng);
/// Nominal force = inverse dynamics of a random acceleration of log-uniform
/// size (1e-3 .. 10 m/s^2), so every case of the QP occurs.
Vector6d RandomNominalForce(const DynamicsTerms& terms, std::mt19937* rng);

/// Relative difference ||a - b|| / max(||b||, 1 N).
double RelativeError(const Vector6d& a, const Vector6d& b);

}  // namespace stewart::safety::test
