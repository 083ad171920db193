#pragma once
// Everything the filter computed at one step (maps 1:1 onto
// stewart::safety_diagnostics_t, see diagnostics_lcm.h). Fixed-size storage.
#include <array>
#include <cstdint>

#include "stewart/safety/barriers.h"
#include "stewart/safety/safety_config.h"
#include "stewart/safety/two_constraint_qp.h"

namespace stewart::safety {

/// Bits of SafetyDiagnostics::flags; equal to force_command_t.FLAG_*.
enum FilterFlag : std::int32_t {
  kFlagFilterActive = 1,   ///< F* != F_des
  kFlagInfeasible = 2,     ///< the QP had no solution; fallback applied
  kFlagFallback = 4,       ///< the safe stop (last resort) was applied
  kFlagInvalidInput = 16,  ///< non-finite or out-of-range q, qd or F_des
  kFlagForceLimited = 64,  ///< an actuator force limit is active at F*
  /// A limit is exceeded (some h < 0): the filter steers back into the safe
  /// set (docs/safety.md, "Outside the safe set").
  kFlagOutsideSafeSet = 128,
  /// F_des asked for more acceleration than one sample period allows
  /// (nominal_bound.h): the conditions were solved for the scaled nominal.
  kFlagNominalBounded = 512,
  /// The composed closed form's answer broke one barrier's own condition;
  /// the un-composed QP answered this step (SafetyConfig::check_each_barrier).
  kFlagPerBarrier = 1024,
};

struct SafetyDiagnostics {
  SafetyVariant variant = SafetyVariant::kClosedForm;
  FilterCase filter_case = FilterCase::kNone;
  bool infeasible = false;
  std::int32_t flags = 0;  ///< FilterFlag bits
  BarrierEvaluation barriers;
  /// KKT multipliers of the two composed conditions. Variant uncomposed: the
  /// sums of its position / velocity rows' multipliers (mu_position,
  /// mu_velocity below), in the same units (docs/safety.md).
  double mu_p = 0.0, mu_v = 0.0;
  /// Variant uncomposed only (zero otherwise): the multiplier of each
  /// barrier's own condition Psi_i(F) = alpha_i (dh_i(F) + h_i) - delta >= 0,
  /// whose gradient is n_i = alpha_i g_i, so that
  /// F* = F_des + W^-1 (sum_i mu_i n_i - mu_force) (uncomposed_qp.h).
  std::array<double, kMaxPositionBarriers> mu_position{};
  std::array<double, kMaxVelocityBarriers> mu_velocity{};
  /// Force-limit multipliers, signed: + upper bound active, - lower.
  /// F* = F_des + mu_p g_p + mu_v g_v - mu_force.
  Vector6d mu_force = Vector6d::Zero();
  Vector6d f_des = Vector6d::Zero();  ///< nominal force as received (N)
  /// F_nom, the nominal the conditions were solved for: F_des within the
  /// per-period bound (nominal_bound.h), F_des itself when nominal_scale is 1.
  /// psi_p, psi_v (barriers) are taken at it, and the KKT multipliers relate
  /// F* to it: F* = F_nom + W^-1 (mu_p g_p + mu_v g_v - mu_force).
  Vector6d f_nominal = Vector6d::Zero();
  Vector6d f_safe = Vector6d::Zero();  ///< F* (N)
  double correction_norm = 0.0;        ///< ||F* - F_des|| (N)
  /// s of the per-period bound (nominal_bound.h): the conditions were solved
  /// for F_0 + s (F_des - F_0); 1 when F_des was within the bound.
  double nominal_scale = 1.0;
  /// Wall time of SafetyFilter::Step (model terms and filter, one pair of
  /// clock reads per step); 0 from StepWithTerms, which is not timed.
  std::int64_t compute_ns = 0;
};

}  // namespace stewart::safety
