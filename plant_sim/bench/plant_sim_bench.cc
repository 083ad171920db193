// Plant alone at 1 kHz control ticks: simulated seconds per wall second,
// with the model's cost for comparison (docs/performance.md, "plant_sim").
// Each iteration is one 1 ms tick with a new ZOH force (so one integrator
// restart), as in a closed-loop run.
#include <benchmark/benchmark.h>

#include <cmath>

#include "stewart/config/default_config.h"
#include "stewart/model/kinematics.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"

namespace stewart {
namespace {

void RunTicks(benchmark::State& state, OdeMethod method, int erk_order = 5) {
  const StackConfig& c = DefaultStackConfig();
  const PlantModel model{c.platform, c.actuators};
  OdeOptions o;
  o.method = method;
  o.rel_tol = c.plant_sim.rel_tol;
  o.abs_tol = c.plant_sim.abs_tol;
  o.erk_order = erk_order;
  Plant plant(model, o);
  const Vector6d q0 = c.plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  const Vector6d hold =
      InverseDynamics(EvaluateDynamics(model.platform, q0, Vector6d::Zero()), Vector6d::Zero());
  const Vector6d l0 = InverseKinematics(model.platform, q0);
  const double dt = 1e-3;
  long ticks = 0;
  for (auto _ : state) {
    // A leg-space PD plus excitation: the plant moves like a controlled one.
    const PlantRates& r = plant.EvaluateRates();
    Vector6d f =
        hold + 2000.0 * (l0 - r.terms.leg_length_m) - 40.0 * (r.terms.H.transpose() * plant.qd());
    f(0) += 3.0 * std::sin(8.0 * ticks * dt);
    plant.SetForceCommand(f);
    plant.Advance(dt);
    ++ticks;
  }
  const PlantCounters k = plant.counters();
  state.counters["rhs_per_tick"] = static_cast<double>(k.ode.rhs_evals) / ticks;
  state.counters["steps_per_tick"] = static_cast<double>(k.ode.steps) / ticks;
  // Simulated seconds per wall second = 1 ms / (wall time per tick).
  state.counters["x_real_time"] =
      benchmark::Counter(static_cast<double>(ticks) * dt, benchmark::Counter::kIsRate);
}

void BM_PlantTick_ArkodeErk(benchmark::State& state) { RunTicks(state, OdeMethod::kArkodeErk); }
void BM_PlantTick_CvodeBdf(benchmark::State& state) { RunTicks(state, OdeMethod::kCvodeBdf); }
void BM_PlantTick_CvodeAdams(benchmark::State& state) { RunTicks(state, OdeMethod::kCvodeAdams); }
BENCHMARK(BM_PlantTick_ArkodeErk);
void BM_PlantTick_ArkodeErkOrder(benchmark::State& state) {
  RunTicks(state, OdeMethod::kArkodeErk, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_PlantTick_ArkodeErkOrder)->Arg(2)->Arg(3)->Arg(4)->Arg(6);
BENCHMARK(BM_PlantTick_CvodeBdf);
BENCHMARK(BM_PlantTick_CvodeAdams);

// Tick plus the sensor sample the process publishes with it.
void BM_PlantTickWithSensors(benchmark::State& state) {
  const StackConfig& c = DefaultStackConfig();
  Plant plant(PlantModel{c.platform, c.actuators}, OdeOptions{});
  SensorModel sensors(c.sensors, c.actuators, c.platform.gravity_mps2);
  const Vector6d q0 = c.plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  const Vector6d hold =
      InverseDynamics(EvaluateDynamics(c.platform, q0, Vector6d::Zero()), Vector6d::Zero());
  const Vector6d l0 = InverseKinematics(c.platform, q0);
  long ticks = 0;
  for (auto _ : state) {
    const PlantRates& r = plant.EvaluateRates();
    const SensorReading s =
        sensors.Sample(plant.q(), plant.qd(), r.x_dot.segment<6>(6), r.terms.leg_length_m);
    benchmark::DoNotOptimize(s);
    // Feedback on the noisy legs, as the stack would close the loop.
    Vector6d f =
        hold + 2000.0 * (l0 - s.leg_length_m) - 40.0 * (r.terms.H.transpose() * plant.qd());
    f(0) += 3.0 * std::sin(8.0 * ticks * 1e-3);
    plant.SetForceCommand(f);
    plant.Advance(1e-3);
    ++ticks;
  }
  state.counters["x_real_time"] =
      benchmark::Counter(static_cast<double>(ticks) * 1e-3, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PlantTickWithSensors);

// The cost units: one model evaluation and one ODE right-hand side.
void BM_EvaluateDynamics(benchmark::State& state) {
  const StackConfig& c = DefaultStackConfig();
  Vector6d qd = Vector6d::Constant(0.01);
  DynamicsTerms terms;
  for (auto _ : state) {
    EvaluateDynamics(c.platform, c.plant_sim.initial_pose, qd, &terms);
    benchmark::DoNotOptimize(terms);
  }
}
BENCHMARK(BM_EvaluateDynamics);

void BM_PlantDerivative(benchmark::State& state) {
  const StackConfig& c = DefaultStackConfig();
  const PlantModel model{c.platform, c.actuators};
  PlantStateVector x = PlantStateVector::Zero();
  x.segment<6>(0) = c.plant_sim.initial_pose;
  x.segment<6>(6).setConstant(0.01);
  PlantInputs u;
  u.force_cmd_n.setConstant(3.0);
  PlantRates r;
  for (auto _ : state) {
    PlantDerivative(model, u, x, &r);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_PlantDerivative);

}  // namespace
}  // namespace stewart

BENCHMARK_MAIN();
