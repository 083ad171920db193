#include "stewart/plant_sim/ode_integrator.h"

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "stewart/plant_sim/serial_vector_kernels.h"

namespace stewart {

OdeOptions OdeOptionsFrom(const PlantSimConfig& config) {
  OdeOptions o;
  o.method = ParseOdeMethod(config.integrator);
  o.rel_tol = config.rel_tol;
  o.abs_tol = config.abs_tol;
  return o;
}

struct OdeIntegrator::Impl {
  OdeRhsFn rhs = nullptr;
  OdeRootFn roots = nullptr;
  void* user_data = nullptr;
  int size = 0;
  int num_roots = 0;
  SUNContext context = nullptr;
  N_Vector y = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver linear_solver = nullptr;
  SUNNonlinearSolver nonlinear_solver = nullptr;
  void* mem = nullptr;
  long reinits = 0;
  long root_returns = 0;
  // Steps and evaluations of earlier segments (a reinit zeroes the counters).
  long steps_before = 0;
  long rhs_before = 0;
  double t = 0.0;

  static int Rhs(realtype t, N_Vector y, N_Vector y_dot, void* self) {
    auto* impl = static_cast<Impl*>(self);
    return impl->rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(y_dot), impl->user_data);
  }
  static int Roots(realtype t, N_Vector y, realtype* g, void* self) {
    auto* impl = static_cast<Impl*>(self);
    return impl->roots(t, N_VGetArrayPointer(y), g, impl->user_data);
  }
  void CountersNow(long* steps, long* rhs_evals) const {
    *steps = 0;
    *rhs_evals = 0;
    if (mem == nullptr) return;
    long s = 0, f = 0;
    if (IsErk()) {
      ERKStepGetNumSteps(mem, &s);
      ERKStepGetNumRhsEvals(mem, &f);
    } else {
      CVodeGetNumSteps(mem, &s);
      CVodeGetNumRhsEvals(mem, &f);
    }
    *steps = s;
    *rhs_evals = f;
  }
  // Both ReInit functions restart the step and evaluation counters.
  void AccumulateCounters() {
    long steps = 0, rhs_evals = 0;
    CountersNow(&steps, &rhs_evals);
    steps_before += steps;
    rhs_before += rhs_evals;
  }
  OdeMethod method = OdeMethod::kArkodeErk;
  bool IsErk() const { return method == OdeMethod::kArkodeErk; }
};

namespace {

void Check(int flag, bool erk, const char* what) {
  if (flag >= 0) return;
  char* name = erk ? ERKStepGetReturnFlagName(flag) : CVodeGetReturnFlagName(flag);
  std::string message =
      std::string(what) + " failed: " + (name ? name : "?") + " (" + std::to_string(flag) + ")";
  // The *GetReturnFlagName functions allocate their result.
  std::free(name);
  throw std::runtime_error(message);
}

}  // namespace

OdeIntegrator::OdeIntegrator(const OdeOptions& options, int size, int num_roots, OdeRhsFn rhs,
                             OdeRootFn roots, void* user_data)
    : impl_(std::make_unique<Impl>()), method_(options.method) {
  Impl& m = *impl_;
  m.method = options.method;
  m.rhs = rhs;
  m.roots = roots;
  m.user_data = user_data;
  m.size = size;
  m.num_roots = num_roots;
  if (SUNContext_Create(nullptr, &m.context) != 0) {
    throw std::runtime_error("SUNContext_Create failed");
  }
  m.y = N_VNew_Serial(size, m.context);
  if (m.y == nullptr) throw std::runtime_error("N_VNew_Serial failed");
  InstallSerialVectorKernels(m.y);  // before any clone: the workspace inherits the kernels
  N_VConst(0.0, m.y);
  const bool erk = m.IsErk();
  if (erk) {
    m.mem = ERKStepCreate(&Impl::Rhs, 0.0, m.y, m.context);
    if (m.mem == nullptr) throw std::runtime_error("ERKStepCreate failed");
    Check(ERKStepSetUserData(m.mem, &m), erk, "ERKStepSetUserData");
    Check(ERKStepSStolerances(m.mem, options.rel_tol, options.abs_tol), erk, "ERKStepSStolerances");
    Check(ERKStepSetOrder(m.mem, options.erk_order), erk, "ERKStepSetOrder");
    Check(ERKStepSetInterpolantType(m.mem, ARK_INTERP_LAGRANGE), erk, "ERKStepSetInterpolantType");
    Check(ERKStepSetMaxNumSteps(m.mem, options.erk_max_steps), erk, "ERKStepSetMaxNumSteps");
    if (num_roots > 0) {
      Check(ERKStepRootInit(m.mem, num_roots, &Impl::Roots), erk, "ERKStepRootInit");
      Check(ERKStepSetNoInactiveRootWarn(m.mem), erk, "ERKStepSetNoInactiveRootWarn");
    }
  } else {
    const bool bdf = options.method == OdeMethod::kCvodeBdf;
    m.mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, m.context);
    if (m.mem == nullptr) throw std::runtime_error("CVodeCreate failed");
    Check(CVodeInit(m.mem, &Impl::Rhs, 0.0, m.y), erk, "CVodeInit");
    Check(CVodeSetUserData(m.mem, &m), erk, "CVodeSetUserData");
    Check(CVodeSStolerances(m.mem, options.rel_tol, options.abs_tol), erk, "CVodeSStolerances");
    Check(CVodeSetMaxNumSteps(m.mem, 100000), erk, "CVodeSetMaxNumSteps");
    if (bdf) {
      m.matrix = SUNDenseMatrix(size, size, m.context);
      m.linear_solver = SUNLinSol_Dense(m.y, m.matrix, m.context);
      if (m.matrix == nullptr || m.linear_solver == nullptr) {
        throw std::runtime_error("SUNDIALS dense linear solver creation failed");
      }
      Check(CVodeSetLinearSolver(m.mem, m.linear_solver, m.matrix), erk, "CVodeSetLinearSolver");
    } else {
      m.nonlinear_solver = SUNNonlinSol_FixedPoint(m.y, 0, m.context);
      if (m.nonlinear_solver == nullptr) throw std::runtime_error("SUNNonlinSol_FixedPoint");
      Check(CVodeSetNonlinearSolver(m.mem, m.nonlinear_solver), erk, "CVodeSetNonlinearSolver");
    }
    if (num_roots > 0) {
      Check(CVodeRootInit(m.mem, num_roots, &Impl::Roots), erk, "CVodeRootInit");
      Check(CVodeSetNoInactiveRootWarn(m.mem), erk, "CVodeSetNoInactiveRootWarn");
    }
  }
}

OdeIntegrator::~OdeIntegrator() {
  Impl& m = *impl_;
  if (m.mem != nullptr) {
    if (m.IsErk()) {
      ERKStepFree(&m.mem);
    } else {
      CVodeFree(&m.mem);
    }
  }
  if (m.nonlinear_solver != nullptr) SUNNonlinSolFree(m.nonlinear_solver);
  if (m.linear_solver != nullptr) SUNLinSolFree(m.linear_solver);
  if (m.matrix != nullptr) SUNMatDestroy(m.matrix);
  if (m.y != nullptr) N_VDestroy(m.y);
  if (m.context != nullptr) SUNContext_Free(&m.context);
}

void OdeIntegrator::Reinit(double t0, const double* y0) {
  Impl& m = *impl_;
  std::copy(y0, y0 + m.size, N_VGetArrayPointer(m.y));
  if (m.IsErk()) {
    // ERKStepReset keeps the step-size history: the step that met the
    // tolerance before the discontinuity is the first one tried after it
    // (an explicit one-step method has no order ramp-up to repeat), and
    // every stage is recomputed from the new right-hand side.
    Check(ERKStepReset(m.mem, t0, m.y), true, "ERKStepReset");
  } else {
    m.AccumulateCounters();
    Check(CVodeReInit(m.mem, t0, m.y), false, "CVodeReInit");
  }
  m.t = t0;
  ++m.reinits;
}

OdeIntegrator::Result OdeIntegrator::Advance(double t_out, double* y, double* t_reached,
                                             int* roots_found) {
  Impl& m = *impl_;
  const bool erk = m.IsErk();
  double t = m.t;
  int flag = 0;
  if (erk) {
    Check(ERKStepSetStopTime(m.mem, t_out), erk, "ERKStepSetStopTime");
    flag = ERKStepEvolve(m.mem, t_out, m.y, &t, ARK_NORMAL);
    Check(flag, erk, "ERKStepEvolve");
  } else {
    Check(CVodeSetStopTime(m.mem, t_out), erk, "CVodeSetStopTime");
    flag = CVode(m.mem, t_out, m.y, &t, CV_NORMAL);
    Check(flag, erk, "CVode");
  }
  m.t = t;
  *t_reached = t;
  std::copy(N_VGetArrayPointer(m.y), N_VGetArrayPointer(m.y) + m.size, y);
  const bool root = erk ? flag == ARK_ROOT_RETURN : flag == CV_ROOT_RETURN;
  if (!root) return Result::kReachedTime;
  ++m.root_returns;
  Check(erk ? ERKStepGetRootInfo(m.mem, roots_found) : CVodeGetRootInfo(m.mem, roots_found), erk,
        "GetRootInfo");
  return Result::kRoot;
}

OdeStats OdeIntegrator::stats() const {
  const Impl& m = *impl_;
  OdeStats s;
  long steps = 0, rhs_evals = 0;
  m.CountersNow(&steps, &rhs_evals);
  s.steps = m.steps_before + steps;
  s.rhs_evals = m.rhs_before + rhs_evals;
  s.reinits = m.reinits;
  s.root_returns = m.root_returns;
  return s;
}

}  // namespace stewart
