// Per-step cost of the safety filter (docs/performance.md, "Safety filter").
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <random>
#include <vector>

#include "stewart/config/default_config.h"
#include "stewart/safety/clp_reference_qp.h"
#include "stewart/safety/safety_filter.h"
#ifdef STEWART_HAVE_ALGLIB
#include "stewart/safety/alglib_reference_qp.h"
#endif

namespace stewart::safety {
namespace {

// A fixed set of states around home with nominal forces that make the filter
// act often (every case occurs), cycled through by every benchmark. The
// accelerations are scaled so that M qdd spreads as on the platform without
// actuator rotors (2 m/s^2 there): with the DC-motor legs' reflected mass
// (config/overlays/p16p.yaml, STEWART_CONFIG) M is ~100 times larger, and
// the unscaled set would ask every leg for kilonewtons.
struct Sample {
  Vector6d q, qd, f_des;
  DynamicsTerms terms;
};
std::vector<Sample> MakeSamples(double accel_scale) {
  std::vector<Sample> s;
  {
    std::mt19937 rng(5);
    std::normal_distribution<double> n;
    const PlatformParams& platform = DefaultStackConfig().platform;
    PlatformParams without_rotors = platform;
    without_rotors.leg.actuator_reflected_mass_kg = 0.0;
    const Vector6d home = DefaultStackConfig().home_pose;
    const double accel_std_mps2 = 2.0 *
                                  EvaluateDynamics(without_rotors, home, Vector6d::Zero()).M(0, 0) /
                                  EvaluateDynamics(platform, home, Vector6d::Zero()).M(0, 0);
    for (int i = 0; i < 256; ++i) {
      Sample x;
      x.q = DefaultStackConfig().home_pose;
      for (int j = 0; j < 3; ++j) x.q(j) += 0.03 * n(rng);
      for (int j = 0; j < 6; ++j) x.qd(j) = 0.008 * n(rng);
      x.terms = EvaluateDynamics(DefaultStackConfig().platform, x.q, x.qd);
      Vector6d qdd;
      for (int j = 0; j < 6; ++j) qdd(j) = accel_scale * accel_std_mps2 * n(rng);
      x.f_des = InverseDynamics(x.terms, qdd);
      s.push_back(x);
    }
  }
  return s;
}

const std::vector<Sample>& Samples() {
  static const std::vector<Sample> samples = MakeSamples(1.0);
  return samples;
}

// Accelerations 20 times larger: many steps reach the force limits.
const std::vector<Sample>& HardSamples() {
  static const std::vector<Sample> samples = MakeSamples(20.0);
  return samples;
}

// The filter on `safety` (the platform and actuators of the config file).
void RunCore(benchmark::State& state, const SafetyConfig& safety) {
  SafetyFilter filter(DefaultStackConfig().platform, safety, DefaultStackConfig().actuators);
  SafetyDiagnostics d;
  size_t i = 0;
  for (auto _ : state) {
    const Sample& s = Samples()[i++ & 255];
    benchmark::DoNotOptimize(filter.StepWithTerms(s.terms, s.q, s.qd, s.f_des, &d));
  }
}

void RunFullStep(benchmark::State& state, const SafetyConfig& safety,
                 ReferenceQpSolver* reference = nullptr) {
  SafetyFilter filter(DefaultStackConfig().platform, safety, DefaultStackConfig().actuators,
                      reference);
  SafetyDiagnostics d;
  // The share of the set whose answer the per-barrier check replaced.
  int replaced = 0;
  for (const Sample& x : Samples()) {
    filter.Step(x.q, x.qd, x.f_des, &d);
    replaced += (d.flags & kFlagPerBarrier) ? 1 : 0;
  }
  size_t i = 0;
  for (auto _ : state) {
    const Sample& x = Samples()[i++ & 255];
    benchmark::DoNotOptimize(filter.Step(x.q, x.qd, x.f_des, &d));
  }
  state.counters["per_barrier_share"] =
      static_cast<double>(replaced) / static_cast<double>(Samples().size());
}

// (a) the closed form given the model terms.
void BM_ClosedFormCore(benchmark::State& state) { RunCore(state, DefaultStackConfig().safety); }
BENCHMARK(BM_ClosedFormCore);

// (a) on the states where a constraint acts only (about half of the set): the
// only steps that solve with H, so the per-step worst case of the closed form.
void BM_ClosedFormCoreActiveOnly(benchmark::State& state) {
  SafetyFilter filter(DefaultStackConfig().platform, DefaultStackConfig().safety,
                      DefaultStackConfig().actuators);
  std::vector<const Sample*> active;
  SafetyDiagnostics d;
  for (const Sample& s : Samples()) {
    filter.StepWithTerms(s.terms, s.q, s.qd, s.f_des, &d);
    if (d.filter_case != FilterCase::kNone) active.push_back(&s);
  }
  size_t i = 0;
  for (auto _ : state) {
    const Sample& s = *active[i++ % active.size()];
    benchmark::DoNotOptimize(filter.StepWithTerms(s.terms, s.q, s.qd, s.f_des, &d));
  }
  state.counters["states"] = static_cast<double>(active.size());
}
BENCHMARK(BM_ClosedFormCoreActiveOnly);

// (b) the full step including M, C qd, G, H.
void BM_ClosedFormFullStep(benchmark::State& state) {
  RunFullStep(state, DefaultStackConfig().safety);
}
BENCHMARK(BM_ClosedFormFullStep);

// (b) without the per-barrier check, and without it and the leg-stroke
// barriers (the shipped config before both, docs/safety.md "Each barrier
// checked").
void BM_ClosedFormFullStepUnchecked(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.check_each_barrier = false;
  s.leg_stroke.enabled = state.range(0) != 0;
  RunFullStep(state, s);
}
BENCHMARK(BM_ClosedFormFullStepUnchecked)->ArgName("leg_stroke")->Arg(1)->Arg(0);

// (b) without the per-period bound on the nominal (nominal_bound.h), and
// without it and the force limits (the shipped config before both).
void BM_ClosedFormFullStepNoNominalBound(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.sample_period_s = 0.0;
  RunFullStep(state, s);
}
BENCHMARK(BM_ClosedFormFullStepNoNominalBound);
void BM_ClosedFormFullStepNoBoundNoForceLimits(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.sample_period_s = 0.0;
  s.force_limits_enabled = false;
  RunFullStep(state, s);
}
BENCHMARK(BM_ClosedFormFullStepNoBoundNoForceLimits);

// (a) with the paper's force metric (no metric map per step).
void BM_ClosedFormCoreForceMetric(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.correction_metric = CorrectionMetric::kForce;
  RunCore(state, s);
}
BENCHMARK(BM_ClosedFormCoreForceMetric);

void BM_PaperRuleCore(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.variant = SafetyVariant::kPaperRule;
  RunCore(state, s);
}
BENCHMARK(BM_PaperRuleCore);

// (c) the QP reference, full step (model terms included, as (b)).
template <typename Solver>
void BM_QpReferenceFullStep(benchmark::State& state) {
  Solver solver;
  SafetyConfig s = DefaultStackConfig().safety;
  s.variant = SafetyVariant::kQpReference;
  RunFullStep(state, s, &solver);
}
BENCHMARK_TEMPLATE(BM_QpReferenceFullStep, ClpReferenceQp);
#ifdef STEWART_HAVE_ALGLIB
BENCHMARK_TEMPLATE(BM_QpReferenceFullStep, AlglibReferenceQp);
#endif

// (d) the force-limited variant (exact dual active set), full step.
void BM_ForceLimitedFullStep(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.force_limits_enabled = true;
  RunFullStep(state, s);
}
BENCHMARK(BM_ForceLimitedFullStep);

// The states of `samples` whose force-limited step meets the limits.
std::vector<const Sample*> ForceLimitedStates(SafetyFilter& filter,
                                              const std::vector<Sample>& samples) {
  std::vector<const Sample*> limited;
  SafetyDiagnostics d;
  for (const Sample& x : samples) {
    filter.Step(x.q, x.qd, x.f_des, &d);
    if (d.flags & kFlagForceLimited) limited.push_back(&x);
  }
  return limited;
}

// A force limit a tenth of the set's states reach: the 90th percentile of
// the largest leg force of the unlimited answers.
double LimitATenthReach(const SafetyConfig& unlimited_config) {
  SafetyConfig s = unlimited_config;
  s.force_limits_enabled = false;
  SafetyFilter filter(DefaultStackConfig().platform, s, DefaultStackConfig().actuators);
  std::vector<double> peak_n;
  SafetyDiagnostics d;
  for (const Sample& x : HardSamples()) {
    peak_n.push_back(filter.Step(x.q, x.qd, x.f_des, &d).cwiseAbs().maxCoeff());
  }
  const auto q75 = peak_n.begin() + static_cast<std::ptrdiff_t>(peak_n.size() * 9 / 10);
  std::nth_element(peak_n.begin(), q75, peak_n.end());
  return *q75;
}

// (d) on states whose unlimited optimum leaves the box only (from a set with
// 20 times the accelerations): the steps that run the active set (the others
// take the closed form and stop), the per-step worst case of the
// force-limited filter. Meant for legs whose limits the set reaches (the
// P-16P overlay, STEWART_CONFIG); where none reaches them (the shipped 100 N)
// the limit is lowered until a tenth of the states do, reported as
// limit_n.
void BM_ForceLimitedFullStepBoxActiveOnly(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.force_limits_enabled = true;
  ActuatorConfig actuators = DefaultStackConfig().actuators;
  std::unique_ptr<SafetyFilter> filter =
      std::make_unique<SafetyFilter>(DefaultStackConfig().platform, s, actuators);
  std::vector<const Sample*> limited = ForceLimitedStates(*filter, HardSamples());
  if (limited.empty()) {
    actuators.force_limit_n = LimitATenthReach(s);
    filter = std::make_unique<SafetyFilter>(DefaultStackConfig().platform, s, actuators);
    limited = ForceLimitedStates(*filter, HardSamples());
  }
  if (limited.empty()) {
    state.SkipWithError("no state of the set reaches the force limits");
    return;
  }
  SafetyDiagnostics d;
  size_t i = 0;
  for (auto _ : state) {
    const Sample& x = *limited[i++ % limited.size()];
    benchmark::DoNotOptimize(filter->Step(x.q, x.qd, x.f_des, &d));
  }
  state.counters["states"] = static_cast<double>(limited.size());
  state.counters["limit_n"] = actuators.force_limit_n;
  // How many of them the un-composed QP answers (the composed answer broke a
  // barrier's own condition): those solve two QPs.
  // And how many have no common point with the limits (the fallback's
  // extra solves).
  int per_barrier = 0, infeasible = 0;
  for (const Sample* x : limited) {
    filter->Step(x->q, x->qd, x->f_des, &d);
    if (d.flags & kFlagPerBarrier) ++per_barrier;
    if (d.infeasible) ++infeasible;
  }
  state.counters["per_barrier"] = per_barrier;
  state.counters["infeasible"] = infeasible;
}
BENCHMARK(BM_ForceLimitedFullStepBoxActiveOnly);

// (e) on states outside the position set where the force-limited conditions
// have no common point (the hard set moved 5 mm beyond x's upper limit, at
// force limits of 1 N, a quarter of the hover force): the steps that relax
// the velocity row by bisection (SafetyFilter::RelaxVelocityLeast), the rare
// worst case. Arg 0: the same states inside the set (the row is dropped).
void BM_ForceLimitedFullStepInfeasibleOnly(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.force_limits_enabled = true;
  ActuatorConfig weak = DefaultStackConfig().actuators;
  weak.force_limit_n = 1.0;
  SafetyFilter filter(DefaultStackConfig().platform, s, weak);
  const bool outside = state.range(0) != 0;
  std::vector<Sample> infeasible;
  SafetyDiagnostics d;
  for (Sample x : HardSamples()) {
    if (outside) {
      x.q(0) = 0.115;  // x <= 0.11 in the shipped config
      x.terms = EvaluateDynamics(DefaultStackConfig().platform, x.q, x.qd);
    }
    filter.Step(x.q, x.qd, x.f_des, &d);
    if (d.infeasible && !(d.flags & kFlagFallback) && d.barriers.outside_position_set == outside) {
      infeasible.push_back(x);
    }
  }
  if (infeasible.empty()) {
    state.SkipWithError("no state of the set is infeasible within the force limits");
    return;
  }
  size_t i = 0;
  for (auto _ : state) {
    const Sample& x = infeasible[i++ % infeasible.size()];
    benchmark::DoNotOptimize(filter.Step(x.q, x.qd, x.f_des, &d));
  }
  state.counters["states"] = static_cast<double>(infeasible.size());
}
BENCHMARK(BM_ForceLimitedFullStepInfeasibleOnly)->ArgName("outside")->Arg(1)->Arg(0);

// The un-composed QP (every barrier its own row, dual active set), full
// step, unlimited and force-limited: what dropping the LSE costs per step.
void BM_UncomposedFullStep(benchmark::State& state) {
  SafetyConfig s = DefaultStackConfig().safety;
  s.variant = SafetyVariant::kUncomposed;
  s.force_limits_enabled = state.range(0) != 0;
  RunFullStep(state, s);
}
BENCHMARK(BM_UncomposedFullStep)->ArgName("force_limits")->Arg(0)->Arg(1);

void BM_ModelTermsOnly(benchmark::State& state) {
  DynamicsTerms t;
  size_t i = 0;
  for (auto _ : state) {
    const Sample& x = Samples()[i++ & 255];
    EvaluateDynamics(DefaultStackConfig().platform, x.q, x.qd, &t);
    benchmark::DoNotOptimize(t);
  }
}
BENCHMARK(BM_ModelTermsOnly);

}  // namespace
}  // namespace stewart::safety

BENCHMARK_MAIN();
