#pragma once
// The safety process's decisions, without LCM: which state estimate a nominal
// command is filtered against, when a command waits for its state, when the
// controller is stale, which fallback goes out and why, what is rejected,
// and the safe command that results. The node (safety/node) only converts
// messages and publishes what this returns; replay and the in-process
// closed loop call the same class, so they decide as the process does.
//
// All timing comes from message utimes (stack time), never the wall clock.
// The state estimates carry it: one whose time is implausible
// (common/input_time_check.h) is rejected before anything else sees it, as
// is a nominal command whose time is implausible against them. OnState and
// OnNominal take the message's receive time (wall clock, us) from the live
// node, nullopt in replay; it only widens the window after a gap and never
// reaches the filter, the watchdog or a command.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>

#include "stewart/common/health_counters.h"
#include "stewart/common/input_time_check.h"
#include "stewart/common/resend_answer.h"
#include "stewart/common/signals.h"
#include "stewart/safety/safety_filter.h"
#include "stewart/safety/supervisor.h"

namespace stewart::safety {

/// One safe command to publish, with the diagnostics of the step that made it.
struct SafetyOutput {
  ForceCommand command;  ///< utime = sample_utime of the state it answers
  /// The node's reason on top of the filter's flags: kCommandStaleInput
  /// (watchdog or stale nominal), kCommandInvalidInput (state not usable),
  /// or 0 for a filtered nominal command.
  int32_t fallback_reason = 0;
  /// The supervisor's mode the command was shaped by (supervisor.h).
  SupervisorMode mode;
  const SafetyDiagnostics* diagnostics = nullptr;  ///< valid until the next call
};

class SafetyProcess {
 public:
  /// `counters` receives rejections and the process counters
  /// (fallback_commands, active_steps, infeasible, nominal_before_state,
  /// hold_commands, drive_off_commands) and must outlive this object;
  /// `reference` as for SafetyFilter; `time`: lcm.time_window_s,
  /// lcm.max_time_rate (a stream of states rejected whole for longer than
  /// safety.stale_age_s is a FAULT). Every command goes through the
  /// supervisor: DISARMED and ESTOP turn the drive off, HOLD sends the safe
  /// stop, ARMING blends the safe stop into the filtered command.
  SafetyProcess(const PlatformParams& platform, const SafetyConfig& safety,
                const ActuatorConfig& actuators, const SupervisorConfig& supervisor,
                ReferenceQpSolver* reference, HealthCounters* counters,
                const TimePlausibilityParams& time = {});

  /// A state estimate arrived. Returns true when `out` holds a command to
  /// publish: the pending nominal command for this state, filtered; or a
  /// fallback (state not usable, or no recent nominal command: the watchdog).
  /// The state whose sample was answered last, received again (a lockstep
  /// resend: the answer was lost), is answered again with the same command
  /// and diagnostics, without a second filter or supervisor step
  /// (common/resend_answer.h; counted `resends_answered`).
  bool OnState(const StateSample& state, SafetyOutput* out,
               std::optional<int64_t> receive_wall_us = std::nullopt);

  /// A nominal command arrived. Returns true when `out` holds a command to
  /// publish: the filtered command, or a fallback for a stale one. A
  /// non-finite one is rejected and counted (`nominal_non_finite`) before it
  /// can be held for its state and displace the real one.
  bool OnNominal(const ForceCommand& nominal, SafetyOutput* out,
                 std::optional<int64_t> receive_wall_us = std::nullopt);

  const SafetyFilter& filter() const { return filter_; }
  /// SafetyFilter::ShareModelTerms.
  void ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared) {
    filter_.ShareModelTerms(std::move(shared));
  }
  /// The supervisor, for operator commands and outside faults (the node,
  /// replay).
  Supervisor& supervisor() { return supervisor_; }
  const Supervisor& supervisor() const { return supervisor_; }
  int64_t stale_age_us() const { return stale_age_us_; }

 private:
  /// The filter step for a nominal command against its state (what OnState
  /// and OnNominal publish when they filter).
  SafetyOutput Filter(const StateSample& state, const ForceCommand& nominal);
  /// The safe stop at `state`, flagged with `reason` (kCommandStaleInput or
  /// kCommandInvalidInput).
  SafetyOutput Fallback(const StateSample& state, int32_t reason);
  const StateSample* FindState(int64_t sample_utime) const;
  bool HandleState(const StateSample& state, SafetyOutput* out,
                   std::optional<int64_t> receive_wall_us);
  bool HandleNominal(const ForceCommand& nominal, SafetyOutput* out,
                     std::optional<int64_t> receive_wall_us);
  /// `out` answers the state (`utime`, `seq`): kept for its resend.
  void Remember(const SafetyOutput& out, int64_t utime, int64_t seq,
                std::optional<int64_t> receive_wall_us);
  /// The supervisor's step, then its mode applied to `force_n` (the
  /// filtered command or the safe stop) at `state`.
  SafetyOutput Supervise(const StateSample& state, const Vector6d& force_n, int64_t sample_utime,
                         int32_t fallback_reason);
  /// Publishing bookkeeping shared by every output.
  SafetyOutput Emit(const Vector6d& force_n, int64_t sample_utime, int32_t flags,
                    int32_t fallback_reason, const SupervisorMode& mode);

  SafetyFilter filter_;
  Supervisor supervisor_;
  SafetyDiagnostics hold_diagnostics_{};  // the safe stop blended in while ARMING
  HealthCounters* counters_;
  const int64_t stale_age_us_;
  InputTimeCheck time_check_;

  // The states the next nominal commands can refer to (a command derives
  // from one state estimate, matched by sample_utime).
  static constexpr int kStateHistory = 64;
  std::array<StateSample, kStateHistory> states_{};
  int states_count_ = 0;
  int states_next_ = 0;
  int64_t newest_state_utime_ = -1;
  /// The newest sample a nominal command answered, among the states that
  /// arrived: a nominal ahead of every state (pending) counts once its state
  /// arrives, so a nominal for a state that never comes cannot feed the
  /// watchdog.
  int64_t newest_nominal_sample_utime_ = -1;
  int64_t last_published_sample_utime_ = -1;
  // A nominal command that arrived before its state (see OnNominal).
  ForceCommand pending_nominal_{};
  bool has_pending_nominal_ = false;
  int64_t first_usable_state_utime_ =
      -1;  ///< first usable state since start or the last unusable one
  int64_t seq_ = 0;
  SafetyDiagnostics diagnostics_{};
  // The last answer and the state it answers. Its diagnostics pointer stays
  // valid: diagnostics_ and hold_diagnostics_ change only in a step that
  // makes a new answer, which replaces it.
  ResendAnswer resend_;
  SafetyOutput last_answer_{};
};

}  // namespace stewart::safety
