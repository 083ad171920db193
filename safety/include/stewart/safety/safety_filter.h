#pragma once
// The CBF safety filter (docs/safety.md):
//
//   F* = argmin (F - F_des)^T W (F - F_des)  s.t.  Psi_p(F) >= 0, Psi_v(F) >= 0
//                                                  [, |F_i| <= F_max]
//
// W = I (the paper's force metric) or H^T M^-1 H (acceleration metric). The
// conditions use the model of the plant including the legs' viscous friction
// when configured: the legs push with F + LegViscousFriction(b, H^T qd).
//
// Typical use in a node (no heap allocation per step):
//   SafetyFilter filter(config.platform, config.safety, config.actuators);
//   SafetyDiagnostics diag;
//   Vector6d f_safe = filter.Step(q, qd, f_des, &diag);
#include <memory>

#include "stewart/model/actuator_params.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/shared_dynamics_terms.h"
#include "stewart/safety/constraint_set.h"
#include "stewart/safety/diagnostics.h"
#include "stewart/safety/filter_workspace.h"
#include "stewart/safety/least_relaxation.h"
#include "stewart/safety/reference_qp.h"
#include "stewart/safety/safety_config.h"
#include "stewart/safety/uncomposed_qp.h"

namespace stewart::safety {

/// |F_des_i| above this (N) is treated as invalid input, not filtered.
constexpr double kMaxInputForceN = 1e7;

/// A solve with H = J_l^T that amplifies its right-hand side by more than
/// this (||H|| ||X|| > 1e8 ||B||, a lower bound of cond(H)) meets a singular
/// configuration of the legs (theta = pi, psi = +-pi/2 at home: docs/safety.md
/// "Implausible poses"): invalid input, zero force, never a force 1e8 times
/// its cause.
constexpr double kMaxLegJacobianCondition = 1e8;

/// Variant qp: a reference correction ||F* - F_nom|| at or below this
/// fraction of max(||F_nom||, 1 N) is the solver's rounding, not an
/// intervention: F* = F_nom, not flagged active (docs/safety.md, "QP
/// reference"). Ten times below the references' stated agreement with the
/// closed form (1e-9), far above what rounding leaves.
constexpr double kReferenceActiveRelTol = 1e-10;

/// Variant closed_form with check_each_barrier: a barrier's own condition at
/// the composed answer F* below -this x (the magnitude of its terms) counts as
/// broken. Far above the rounding of the composed solve, far below any
/// physical margin.
constexpr double kPerBarrierRelTol = 1e-9;

class SafetyFilter {
 public:
  /// Throws InputError (a std::invalid_argument naming the config key) for an
  /// unusable config, or variant "qp" without a reference solver (which must
  /// outlive the filter).
  SafetyFilter(const PlatformParams& platform, const SafetyConfig& safety,
               const ActuatorConfig& actuators, ReferenceQpSolver* reference = nullptr);

  /// Evaluates the model through `shared` (in process: the estimator and
  /// the controller evaluate it at the same estimates). std::invalid_argument
  /// when its parameters are not this filter's; null: its own.
  void ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared);

  /// Full step: evaluates the model terms at (q, qd), then StepWithTerms.
  /// Output is always finite; see diagnostics->flags. diagnostics->compute_ns
  /// is the wall time of this whole call (model terms included).
  Vector6d Step(const Vector6d& q, const Vector6d& qd, const Vector6d& f_des,
                SafetyDiagnostics* diagnostics);
  /// The same with the state's estimate of the model error d (barriers.h);
  /// ignored when safety.use_disturbance_estimate is false. A non-finite or
  /// negative-std estimate is invalid input (the safe stop, flagged).
  Vector6d Step(const Vector6d& q, const Vector6d& qd, const Vector6d& f_des,
                const GeneralizedDisturbance& disturbance, SafetyDiagnostics* diagnostics);

  /// The filter given the model terms at (q, qd) (from EvaluateDynamics).
  /// Not timed: diagnostics->compute_ns is set to 0 (Step times the step,
  /// and a clock read is not negligible against this call: docs/performance.md).
  Vector6d StepWithTerms(const DynamicsTerms& terms, const Vector6d& q, const Vector6d& qd,
                         const Vector6d& f_des, SafetyDiagnostics* diagnostics) const;
  Vector6d StepWithTerms(const DynamicsTerms& terms, const Vector6d& q, const Vector6d& qd,
                         const Vector6d& f_des, const GeneralizedDisturbance& disturbance,
                         SafetyDiagnostics* diagnostics) const;

  /// The configured safe stop at (q, qd), for when no usable nominal command
  /// exists (stale or missing): flagged kFlagFallback, case kFallback. Zero
  /// force if the state is not finite or its pose not plausible
  /// (pose_plausibility.h).
  Vector6d SafeStopCommand(const Vector6d& q, const Vector6d& qd, SafetyDiagnostics* diagnostics);
  /// The same, holding against the estimated model error d too (ignored
  /// when not finite or when safety.use_disturbance_estimate is false).
  Vector6d SafeStopCommand(const Vector6d& q, const Vector6d& qd,
                           const GeneralizedDisturbance& disturbance,
                           SafetyDiagnostics* diagnostics);

  /// The safe stop when the drive comes on (the supervisor's ARMING starts
  /// from it). While the legs were held nothing showed the estimator what
  /// the platform weighs: d_z may be anywhere within safety.disturbance_sigma
  /// standard deviations of its estimate. The hold is computed with d_z
  /// shifted towards the configured z velocity limit (up for an upper
  /// limit) by as much of k sigma_z as the limit cannot absorb within
  /// safety.drive_on_response_s:
  ///   shift = max(0, k sigma_z - m_z (zd_max - zd) / T),  m_z = 1 / (M^-1)_zz,
  /// so a platform lighter than the model reaches at most the limit before
  /// the estimate sees it move, and sinks rather than lifts when far
  /// lighter (docs/safety.md, "Drive-on"). Once the estimate has seen the
  /// platform move, sigma_z is small and this is SafeStopCommand. No shift
  /// when z has velocity limits on both sides or none, without the
  /// disturbance estimate, or with T = 0. Diagnostics as SafeStopCommand's.
  Vector6d DriveOnCommand(const Vector6d& q, const Vector6d& qd,
                          const GeneralizedDisturbance& disturbance,
                          SafetyDiagnostics* diagnostics);
  /// The shift DriveOnCommand adds to d^_z at (q, qd) (N, signed; 0 when
  /// none applies or the model terms are not usable).
  double DriveOnShiftN(const Vector6d& q, const Vector6d& qd,
                       const GeneralizedDisturbance& disturbance);

  /// T of the correction metric at these model terms (docs/safety.md): with
  /// F = T y the cost (F - F_des)^T W (F - F_des) is ||y - y_des||^2, and
  /// W^-1 = T T^T. Identity for the force metric; H^-1 L_M (M = L_M L_M^T)
  /// for the acceleration metric, NaN there when M is not positive definite
  /// or H is singular. The unlimited closed form never forms T (it works
  /// with the Gram matrix of T^T g_p, T^T g_v, which needs no H^-1); the
  /// force-limited variant and the QP reference compute it per step.
  Matrix6d MetricMap(const DynamicsTerms& terms) const;

  /// The QP the filter solves at this step, as posed to the reference solver:
  /// in the metric's coordinates y = T^-1 F (T = MetricMap(terms), so
  /// ||y - y0||^2 is the metric's cost; y = F for the force metric), CBF rows
  /// scaled to unit normals, box rows when force limits are on. Map a
  /// solution back with ForceFromQpSolution.
  /// Absent rows are left out; returns false when a CBF row has a zero
  /// normal (it cannot be posed).
  using QpRows = safety::QpRows;
  bool BuildQp(const Matrix6d& metric_map, const BarrierEvaluation& barriers, const Vector6d& f_des,
               ProjectionQp* qp, QpRows* rows = nullptr) const;

  /// The un-composed QP at this step (uncomposed_qp.h, variant uncomposed):
  /// one row per barrier, alpha_i (dh_i(F) + h_i) >= delta_group, evaluated
  /// like the composed conditions at the net force F + friction, in the same
  /// coordinates y = T^-1 F as BuildQp, rows T^T alpha_i g_i scaled to unit
  /// normals, then the box rows when force limits are on. `barriers` must come
  /// from the filter at the same (q, qd, F_des) (SafetyDiagnostics::barriers).
  /// Rows with a zero normal are left out; returns false when one of them is
  /// violated (no force can satisfy it).
  bool BuildUncomposedQp(const DynamicsTerms& terms, const Vector6d& qd, const Matrix6d& metric_map,
                         const BarrierEvaluation& barriers, const Vector6d& f_des, UncomposedQp* qp,
                         UncomposedQpRows* rows = nullptr) const;

  /// F = T y for a solution y of the QP from BuildQp or BuildUncomposedQp.
  static Vector6d ForceFromQpSolution(const Matrix6d& metric_map, const Vector6d& y) {
    return metric_map * y;
  }
  /// The filter's output from the exact solver's y: F_des itself when the
  /// solver left y0 = T^-1 F_des as it was (no row violated), since T T^-1
  /// F_des differs from F_des by rounding and would read as an intervention.
  static Vector6d ForceFromQpSolution(const Matrix6d& metric_map, const Vector6d& y,
                                      const Vector6d& y0, const Vector6d& f_des) {
    return y == y0 ? f_des : ForceFromQpSolution(metric_map, y);
  }

  void set_variant(SafetyVariant variant);
  SafetyVariant variant() const { return variant_; }
  void set_force_limits(bool enabled) { force_limits_ = enabled; }
  void set_check_each_barrier(bool enabled) { check_each_barrier_ = enabled; }
  bool check_each_barrier() const { return check_each_barrier_; }
  bool force_limits() const { return force_limits_; }
  const ConstraintSet& constraints() const { return constraints_; }
  CorrectionMetric correction_metric() const { return metric_; }
  double leg_friction_nspm() const { return leg_friction_nspm_; }
  double force_limit_n() const { return force_limit_n_; }
  /// Largest model acceleration per axis a nominal may ask for (m/s^2,
  /// rad/s^2; nominal_bound.h): +Inf on every axis when the bound is off.
  const Vector6d& nominal_max_accel() const { return nominal_max_accel_; }

 private:
  /// The inputs of one step, as the private steps read them.
  struct StepInput {
    const DynamicsTerms& terms;
    const Vector6d& qd;
    const Vector6d& f_des;
    const BarrierEvaluation& barriers;
    const Vector6d& disturbance_n;  ///< d the safe stop holds against (0 if unused)
  };

  /// The model terms at (q, qd) into workspace_.terms; false when the state
  /// is not finite, M is not, or the pose is not plausible.
  bool EvaluateSafeStopTerms(const Vector6d& q, const Vector6d& qd);
  /// The safe stop at workspace_.terms against d with `shift_z_n` added to
  /// its z row, with its diagnostics.
  Vector6d SafeStopWithShift(bool terms_valid, const Vector6d& qd,
                             const GeneralizedDisturbance& disturbance, double shift_z_n,
                             SafetyDiagnostics* d) const;
  double DriveOnShift(const DynamicsTerms& terms, const Vector6d& qd,
                      const GeneralizedDisturbance& disturbance) const;
  Vector6d SafeStop(const DynamicsTerms& terms, const Vector6d& qd, bool terms_valid,
                    const Vector6d& disturbance_n) const;
  /// The safe stop as the answer of a step whose QP has no solution.
  void ApplySafeStop(const StepInput& in, SafetyDiagnostics* d) const;
  /// The step's T, L and H factor in `ws` (ComputeMetricMap), and the flag
  /// that lets the un-composed posing reuse that L.
  bool ComputeStepMetricMap(const DynamicsTerms& terms, FilterWorkspace* ws) const;
  /// The factor L of the metric's map T = H^-1 L (not the force metric's):
  /// L_M with M = L_M L_M^T for the kinetic metric (acceleration), M itself
  /// for task accelerations. Needs x.inertia_valid for the kinetic metric.
  Matrix6d MetricFactor(const DynamicsTerms& terms, const BarrierIntermediates& x) const;
  /// T into `map` (and its factor L into `l`, except for the force metric).
  bool ComputeMetricMap(const DynamicsTerms& terms, const BarrierIntermediates& x,
                        LegJacobianFactor* factor, Matrix6d* l, Matrix6d* map) const;
  void SolveUnlimited(const StepInput& in, const FilterWorkspace& ws, SafetyDiagnostics* d) const;
  /// ws->problem from the barriers and ws->metric_map.
  void ComposeProblem(const BarrierEvaluation& b, FilterWorkspace* ws) const;
  /// y = T^-1 f in the metric's coordinates from the factor of M in `x`
  /// (f itself for the force metric; NaN without a factor).
  Vector6d MetricCoordinates(const Vector6d& f, const Matrix6d& h,
                             const BarrierIntermediates& x) const;
  /// ws->composed.qp and .rows from ws->problem and ws->metric_map; y0 =
  /// T^-1 F_des (MetricCoordinates, or a solve with T where M has no factor).
  bool PoseQp(const Vector6d& y0, ConditionGroups groups, FilterWorkspace* ws) const;
  void SolveForceLimited(const StepInput& in, FilterWorkspace* ws, SafetyDiagnostics* d) const;
  /// Where the velocity condition, the position condition and the box have
  /// no common point, outside the position set: replaces ws->composed's answer to the position row
  /// and the box alone by the projection of y0 onto them with the velocity row relaxed by the least
  /// amount they allow (within kRelaxationRelTol of the shortfall of that answer), so that the
  /// velocity condition, which holds the recovery barriers outside the position set, is missed as
  /// little as the actuators allow.
  void RelaxVelocityLeast(const Vector6d& y0, FilterWorkspace* ws) const;
  void SolveReference(const StepInput& in, FilterWorkspace* ws, SafetyDiagnostics* d) const;
  /// `out` posed from ws.barrier.inertia and ws.metric_map.
  bool PoseUncomposedQp(const StepInput& in, ConditionGroups groups, const FilterWorkspace& ws,
                        UncomposedQpData* out) const;
  void SolveUncomposed(const StepInput& in, FilterWorkspace* ws, SafetyDiagnostics* d) const;
  /// The un-composed RelaxVelocityLeast: replaces ws->uncomposed's answer to
  /// the position rows and the box alone by the projection of y0 onto them
  /// and every velocity row relaxed by one common distance in the metric,
  /// the least they allow (within kRelaxationRelTol of that answer's worst
  /// miss). Uses ws->velocity_alone for the posing.
  void RelaxUncomposedVelocityLeast(const StepInput& in, FilterWorkspace* ws) const;
  /// True when F breaks some barrier's own condition Psi_i(F) >= 0 (the rows
  /// of PoseUncomposedQp) beyond rounding (kPerBarrierRelTol).
  bool BreaksABarrierCondition(const StepInput& in, const FilterWorkspace& ws,
                               const Vector6d& f) const;
  /// The report of a QP solution, for every variant that solves one: from the
  /// group multipliers d->mu_p, d->mu_v, the case; from the force-limit rows'
  /// multipliers (lower, upper per leg; nullptr when none were posed or the
  /// solver gives none), d->mu_force and kFlagForceLimited.
  static void ReportQpSolution(const double* force_limit_mu, SafetyDiagnostics* d);
  // Flags and correction norm of a finished step.
  static void FinishStep(const Vector6d& f_des, SafetyDiagnostics* d);
  /// The multiplier of a condition posed as a unit-normal row (`row` -1: not posed).
  static double ConditionMultiplier(const double* row_mu, int row, double norm) {
    return row >= 0 ? row_mu[row] / norm : 0.0;
  }

  PlatformParams platform_;
  std::shared_ptr<SharedDynamicsTerms> shared_terms_;
  ConstraintSet constraints_;
  SafetyVariant variant_;
  CorrectionMetric metric_;
  double leg_friction_nspm_;
  bool force_limits_;
  double force_limit_n_;
  SafetyFallback fallback_;
  double stop_time_s_;
  double drive_on_response_s_;
  bool use_disturbance_;
  bool check_each_barrier_;
  Vector6d nominal_max_accel_;
  bool bound_nominal_;
  ReferenceQpSolver* reference_;
  /// The data of the step under way (filter_workspace.h): written by every
  /// step before it is read, so a const step changes nothing observable.
  /// Like the model terms it holds, it makes a filter one step at a time:
  /// not to be stepped from two threads at once.
  mutable FilterWorkspace workspace_;
};

}  // namespace stewart::safety
