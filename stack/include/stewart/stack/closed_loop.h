#pragma once
// The control loop of the stack, run in one process (no LCM). Used by
// stewart_closed_loop_sim and by tests that need many closed-loop runs.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "stewart/config/stack_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/model/types.h"
#include "stewart/safety/reference_qp.h"
#include "stewart/safety/two_constraint_qp.h"

namespace stewart {

struct ClosedLoopOptions {
  double duration_s = 40.0;
  bool perfect_state = false;  ///< ground truth to controller and filter instead of the EKF
  bool no_filter = false;      ///< F* = F_des (to measure what the filter prevents)
  /// The estimator, the controller and the filter evaluate the model once
  /// per estimate between them (SharedDynamicsTerms: the same terms, bit
  /// for bit, as three evaluations); false: each its own.
  bool share_model_terms = true;
  /// The reference solver for variant qp (must outlive the run); unused otherwise.
  safety::ReferenceQpSolver* reference = nullptr;
  std::uint64_t seed = 1;  ///< sensor noise seed (overrides sensors.seed)
  /// The plant's physics; absent: the config's own (TruthOfConfig). The
  /// estimator, controller and filter always use `config`.
  std::optional<PlantTruth> truth;
  /// An attacker on CMD_NOMINAL: called with each tick's nominal force (N)
  /// before safety filters it; may replace it (tests of the per-period
  /// bound, docs/safety.md "One sample period").
  std::function<void(long tick, Vector6d* force_n)> forge_nominal;
};

/// One configured limit and how close ground truth came to it over a run:
/// the smallest value of (upper - value) or (value - lower) (m or m/s,
/// negative when the limit was exceeded).
struct LimitMargin {
  std::string name;  ///< "x_upper", "zd_upper", ... (axis, d for a rate, side)
  double worst_margin = 1e9;
  double excess() const { return worst_margin < 0.0 ? -worst_margin : 0.0; }
};

/// The names of the config's limits, in the order ClosedLoopSummary reports
/// them: position limits, then velocity limits, upper before lower.
std::vector<std::string> LimitNames(const SafetyConfig& safety);

struct ClosedLoopSummary {
  bool completed = false;
  long ticks = 0;
  Vector6d q_max = Vector6d::Constant(-1e9), q_min = Vector6d::Constant(1e9);    ///< ground truth
  Vector6d qd_max = Vector6d::Constant(-1e9), qd_min = Vector6d::Constant(1e9);  ///< ground truth
  double max_limit_excess = -1e9;          ///< largest excess of any configured limit (m or m/s)
  std::string max_limit_excess_name;       ///< which limit, e.g. "xd upper"
  std::vector<LimitMargin> limit_margins;  ///< every limit, LimitNames order
  std::string failure;  ///< why the run stopped early (plant integration), "" if it did not
  /// Model evaluations the stack's components made between them and how
  /// many more answered from the shared terms (0 without sharing).
  long model_evaluations = 0;
  long model_evaluations_shared = 0;
  double rms_q_error = 0.0;               ///< estimate vs truth, translations (m)
  double rms_qd_error = 0.0;              ///< estimate vs truth, translational rates (m/s)
  safety::FilterCaseCounts case_ticks{};  ///< ticks per FilterCase
  long infeasible_ticks = 0;
  /// Ticks whose nominal exceeded the per-period bound (FLAG_NOMINAL_BOUNDED).
  long nominal_bounded_ticks = 0;
  /// Ticks the un-composed QP answered because the composed answer broke a
  /// barrier's own condition (FLAG_PER_BARRIER).
  long per_barrier_ticks = 0;
  long fallback_ticks = 0;  ///< ticks the safety process answered with its fallback
  long endstop_hits = 0;    ///< legs entering an end-stop (plant)
  /// The plant's legs against the stroke the filter's leg-stroke barriers
  /// keep them in (the config's stroke drawn in by safety.leg_stroke.margin_m
  /// at each end): the smallest distance inside it over the run (m),
  /// negative when a leg went beyond it. 1e9 without leg-stroke barriers.
  double leg_stroke_worst_margin_m = 1e9;
  long stiff_fallbacks = 0;  ///< plant intervals the BDF fallback integrated (Plant)
  /// Stack time the supervisor spent ARMING or ARMED (its motion clock, s):
  /// 0 when it never armed (it refuses without a usable estimate or outside a
  /// limit nothing steers back from, docs/operations.md "Arming and e-stop"), and the run then
  /// shows the plant with its drive off, not the stack.
  double armed_s = 0.0;
  long estimator_rejections = 0;  ///< sensor samples or updates the estimator rejected
  long saturated_ticks = 0;       ///< ticks where |F*_i| exceeded the actuator force limit
  double max_force_n = 0.0;
  long estimator_reinits = 0;
  Vector6d q_final = Vector6d::Zero();
  // What the filter costs (docs/safety.md, "The un-composed QP"):
  long filtered_ticks = 0;        ///< ticks the filter ran on a nominal command
  long active_ticks = 0;          ///< of those, ticks with F* != F_des
  double sum_correction_n = 0.0;  ///< sum of ||F* - F_des|| over filtered ticks (N)
  double period_s = 0.0;          ///< control period (s)
  /// Per axis: ticks where that axis' setpoint is inside its position limits
  /// (always, for an axis without limits), and the RMS of q_true - q_des over
  /// them (m, rad): the tracking the filter should not cost.
  std::array<long, kNumAxes> inside_ticks{};
  Vector6d rms_tracking_error_inside = Vector6d::Zero();
  /// The same over x, y and z together: sqrt(sum of squares / ticks) (m).
  double rms_translation_tracking_inside_m = 0.0;
  double mean_correction_n() const {
    return filtered_ticks > 0 ? sum_correction_n / static_cast<double>(filtered_ticks) : 0.0;
  }
  double active_time_s() const { return static_cast<double>(active_ticks) * period_s; }
};

/// Runs `scenario` for options.duration_s at the sensor rate. `csv`, when not
/// null, receives one line per tick. Throws on invalid config; a plant
/// integration failure ends the run with `failure` set, not completed.
ClosedLoopSummary RunClosedLoop(const StackConfig& config, const Scenario& scenario,
                                const ClosedLoopOptions& options, std::ostream* csv);

/// Human-readable table: per axis the extremes against the configured limits.
std::string FormatSummary(const StackConfig& config, const ClosedLoopSummary& summary);

}  // namespace stewart
