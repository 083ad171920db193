// Benchmarks of the model terms that sit on every process's hot path.
#include <benchmark/benchmark.h>

#include "stewart/config/default_config.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

Vector6d TestPose() {
  Vector6d q;
  q << 0.03, -0.02, 0.43, 0.05, -0.04, 0.08;
  return q;
}

Vector6d TestVelocity() {
  Vector6d qd;
  qd << 0.01, 0.02, -0.01, 0.1, -0.05, 0.07;
  return qd;
}

/// M, C qd, G and H at the test state.
DynamicsTerms TestTerms() {
  return EvaluateDynamics(DefaultStackConfig().platform, TestPose(), TestVelocity());
}

void BM_InverseKinematics(benchmark::State& state) {
  const PlatformParams& p = DefaultStackConfig().platform;
  const Vector6d q = TestPose();
  for (auto _ : state) benchmark::DoNotOptimize(InverseKinematics(p, q));
}
BENCHMARK(BM_InverseKinematics);

void BM_ForwardKinematics(benchmark::State& state) {
  const PlatformParams& p = DefaultStackConfig().platform;
  const Vector6d q = TestPose();
  const Vector6d lengths = InverseKinematics(p, q);
  const Vector6d guess = DefaultStackConfig().home_pose;  // a cold start, 4-5 Newton steps
  for (auto _ : state) benchmark::DoNotOptimize(ForwardKinematics(p, lengths, guess));
}
BENCHMARK(BM_ForwardKinematics);

void BM_ForwardKinematicsWarm(benchmark::State& state) {
  const PlatformParams& p = DefaultStackConfig().platform;
  const Vector6d q = TestPose();
  const Vector6d lengths = InverseKinematics(p, q);
  Vector6d guess = q;
  guess(0) += 1e-4;  // the previous tick's pose: how a 1 kHz loop uses FK
  for (auto _ : state) benchmark::DoNotOptimize(ForwardKinematics(p, lengths, guess));
}
BENCHMARK(BM_ForwardKinematicsWarm);

// M, C qd, G and H: the terms every process needs at each tick.
void BM_DynamicsTerms(benchmark::State& state) {
  const PlatformParams& p = DefaultStackConfig().platform;
  const Vector6d q = TestPose();
  const Vector6d qd = TestVelocity();
  DynamicsTerms terms;
  for (auto _ : state) {
    EvaluateDynamics(p, q, qd, &terms);
    benchmark::DoNotOptimize(terms);
  }
}
BENCHMARK(BM_DynamicsTerms);

void BM_ForwardDynamics(benchmark::State& state) {
  const DynamicsTerms terms = TestTerms();
  Vector6d force = Vector6d::Constant(3.0);
  for (auto _ : state) benchmark::DoNotOptimize(ForwardDynamics(terms, force));
}
BENCHMARK(BM_ForwardDynamics);

void BM_InverseDynamics(benchmark::State& state) {
  const DynamicsTerms terms = TestTerms();
  Vector6d qdd = Vector6d::Constant(0.1);
  for (auto _ : state) benchmark::DoNotOptimize(InverseDynamics(terms, qdd));
}
BENCHMARK(BM_InverseDynamics);

}  // namespace
}  // namespace stewart

BENCHMARK_MAIN();
