#pragma once
// A thin RAII wrapper over the SUNDIALS 6.4 integrators the simulator can
// use (docs/simulation.md, "Integrator", says which and why):
//   kArkodeErk   ARKODE ERKStep, explicit adaptive Runge-Kutta, order 5
//                (Cash-Karp 6-4-5); a restart (ERKStepReset) keeps the step
//                size, so a restart at every force change costs one extra
//                right-hand side and one control tick is usually one step.
//   kCvodeBdf    CVODE BDF (orders 1-5) with a dense direct linear solver.
//   kCvodeAdams  CVODE Adams-Moulton (orders 1-12), fixed-point iteration.
// The system size and the number of root functions are fixed at construction.
#include <memory>
#include <string>

#include "stewart/common/enum_table.h"
#include "stewart/plant_sim/plant_sim_config.h"

namespace stewart {

enum class OdeMethod { kArkodeErk, kCvodeBdf, kCvodeAdams };
inline constexpr EnumTable<OdeMethod, 3> kOdeMethodNames{{{
    {OdeMethod::kArkodeErk, "arkode_erk"},
    {OdeMethod::kCvodeBdf, "cvode_bdf"},
    {OdeMethod::kCvodeAdams, "cvode_adams"},
}}};

/// Throws InputError (an std::invalid_argument) listing the names.
inline OdeMethod ParseOdeMethod(const std::string& name) {
  return kOdeMethodNames.Parse(name, "integrator");
}
inline std::string ToString(OdeMethod method) { return std::string(kOdeMethodNames.Name(method)); }

/// y' = f(t, y). Return 0 on success, > 0 for a recoverable failure (the
/// integrator retries with a smaller step), < 0 to abort.
using OdeRhsFn = int (*)(double t, const double* y, double* y_dot, void* user_data);
/// g(t, y): the integrator stops where any g_i changes sign.
using OdeRootFn = int (*)(double t, const double* y, double* g, void* user_data);

struct OdeStats {
  long steps = 0;
  long rhs_evals = 0;
  long reinits = 0;
  long root_returns = 0;
};

struct OdeOptions {
  OdeMethod method = OdeMethod::kArkodeErk;
  double rel_tol = 1e-8;
  double abs_tol = 1e-10;
  int erk_order = 5;  ///< kArkodeErk only: ARKODE's default table of this order (2-8)
  /// kArkodeErk only: the steps the explicit method may take towards one
  /// output time before it gives up (Plant then integrates that interval
  /// with its stiff fallback).
  long erk_max_steps = 100000;
};

/// The integrator and tolerances of the `plant_sim` section; throws
/// std::invalid_argument for an unknown integrator.
OdeOptions OdeOptionsFrom(const PlantSimConfig& config);

class OdeIntegrator {
 public:
  OdeIntegrator(const OdeOptions& options, int size, int num_roots, OdeRhsFn rhs, OdeRootFn roots,
                void* user_data);
  ~OdeIntegrator();
  OdeIntegrator(const OdeIntegrator&) = delete;
  OdeIntegrator& operator=(const OdeIntegrator&) = delete;

  /// Restarts the integration at (t0, y0): no history of the previous
  /// right-hand side survives, as needed after any discontinuity.
  void Reinit(double t0, const double* y0);

  enum class Result { kReachedTime, kRoot };
  /// Integrates from the current time towards t_out, never past it. Stops
  /// early at a root: then `roots_found[i]` is +1 / -1 (g_i rising /
  /// falling) or 0. Writes y and the time reached. Throws
  /// std::runtime_error naming the SUNDIALS error on failure.
  Result Advance(double t_out, double* y, double* t_reached, int* roots_found);

  OdeMethod method() const { return method_; }
  OdeStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  OdeMethod method_;
};

}  // namespace stewart
