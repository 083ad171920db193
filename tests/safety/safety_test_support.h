#pragma once
// Configs and random states shared by the safety filter tests.
#include <random>

#include "stewart/config/stack_config.h"
#include "stewart/model/dynamics.h"
#include "stewart/safety/safety_filter.h"
#include "stewart/safety/supervisor.h"

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

/// KKT of the force limits on an output F*: |F_i| <= f_max_n, and a
/// non-zero multiplier only on a limit that holds with equality (sign: +
/// upper, - lower); all zero without force limits. gtest EXPECTs.
void ExpectForceLimitsKkt(const Vector6d& f, const Vector6d& mu_force, bool force_limits,
                          double f_max_n, int sample);

/// A filter on the rich config with this variant and force-limit switch.
SafetyFilter MakeRichFilter(bool force_limits = false,
                            SafetyVariant variant = SafetyVariant::kClosedForm);

/// One filter input with its model terms.
struct FilterInput {
  Vector6d q, qd, f_des;
  DynamicsTerms terms;
};
/// RandomPoseInLimits, RandomVelocity, the terms there, RandomNominalForce.
FilterInput RandomFilterInput(std::mt19937* rng);

/// At rest at the home pose, with the nominal force that accelerates along +x
/// by `accel_mps2` (inverse dynamics).
FilterInput AtRestPushedAlongX(double accel_mps2);

/// The leg forces that hold the platform at rest at q (H F = G).
Vector6d HoverForce(const Vector6d& q);

/// A supervisor that arms by itself at the first filtered step, at once (no
/// ramp), and latches the first fallback while moving: for tests about what
/// the safety process answers, not about arming.
SupervisorConfig ArmedAtOnce();

/// Relative difference ||a - b|| / max(||b||, 1 N).
double RelativeError(const Vector6d& a, const Vector6d& b);

}  // namespace stewart::safety::test
