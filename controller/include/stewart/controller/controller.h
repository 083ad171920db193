#pragma once
// The controller's state machine, free of LCM: setpoint source (scenario or
// live), workspace rejection, time from the state's utime, and the control law.
#include <cstdint>
#include <memory>
#include <optional>

#include "stewart/common/enum_table.h"
#include "stewart/controller/control_law.h"
#include "stewart/controller/controller_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/model/dynamics.h"

namespace stewart {

enum class SetpointStatus { kAccepted, kNonFinite, kOutsideWorkspace };
enum class StepStatus { kOk, kNonFiniteState, kTimeNotIncreasing, kNonFiniteForce };

inline constexpr EnumTable<SetpointStatus, 3> kSetpointStatusNames{{{
    {SetpointStatus::kAccepted, "accepted"},
    {SetpointStatus::kNonFinite, "setpoint_non_finite"},
    {SetpointStatus::kOutsideWorkspace, "setpoint_outside_workspace"},
}}};
inline constexpr EnumTable<StepStatus, 4> kStepStatusNames{{{
    {StepStatus::kOk, "ok"},
    {StepStatus::kNonFiniteState, "state_non_finite"},
    {StepStatus::kTimeNotIncreasing, "state_time_not_increasing"},
    {StepStatus::kNonFiniteForce, "force_non_finite"},
}}};
/// The names health_t counts rejections under.
inline const char* ToString(SetpointStatus status) {
  return kSetpointStatusNames.Name(status).data();
}
inline const char* ToString(StepStatus status) { return kStepStatusNames.Name(status).data(); }

struct ControllerOutput {
  Vector6d force_n = Vector6d::Zero();  ///< F_des (N)
  Setpoint setpoint;                    ///< the setpoint F_des tracks
  /// The latest requested setpoint (live message or scenario sample) was
  /// rejected; `setpoint` is the last valid one (or the home pose).
  bool setpoint_rejected = false;
  /// Scenario mode: this step's scenario sample was rejected (count it).
  std::optional<SetpointStatus> scenario_rejection;
  double scenario_time_s =
      0.0;  ///< scenario time t (s): the motion clock, else since the first valid state
};

class Controller {
 public:
  /// Without a scenario, setpoints come from OfferSetpoint (live); until the
  /// first valid one arrives the controller holds `home_pose`.
  Controller(const PlatformParams& platform, const ControllerConfig& gains,
             const Vector6d& home_pose, std::optional<Scenario> scenario = std::nullopt);

  /// Live mode: checks the setpoint and adopts it if valid; a rejected one
  /// keeps the last valid setpoint. When following a scenario it only
  /// returns the check (scenario nodes do not subscribe to live setpoints).
  SetpointStatus OfferSetpoint(const Setpoint& setpoint);

  /// One control step for the state at `utime` (us). On kOk fills `out`; on
  /// any other status `out` is untouched and nothing must be published.
  StepStatus Step(int64_t utime, const Vector6d& q, const Vector6d& qd, ControllerOutput* out);
  /// The same with the state's estimate of the model error d (N, N m per rad;
  /// model/disturbance.h), cancelled when gains.compensate_disturbance.
  StepStatus Step(int64_t utime, const Vector6d& q, const Vector6d& qd,
                  const Vector6d& disturbance_n, ControllerOutput* out);

  /// The supervisor's motion clock (supervisor_state_t): at stack time
  /// `utime` (us) the platform had moved for `motion_time_us`, and keeps
  /// moving (`running`: ARMING or ARMED) or not. From the first call on, a
  /// scenario runs on this clock instead of the time since the first state:
  /// it pauses while the platform holds, and a restarted controller takes
  /// the scenario up where the motion was, not from t = 0.
  void SetMotionClock(int64_t utime, int64_t motion_time_us, bool running);
  /// Makes the scenario start at t = 0 at the motion clock's first reading
  /// (a scenario replayed from its start after this process restarts).
  void RestartScenarioAtFirstMotionClock() { restart_at_first_clock_ = true; }

  bool following_scenario() const { return scenario_.has_value(); }
  const std::optional<Scenario>& scenario() const { return scenario_; }
  /// True once a state at t >= duration_s has been processed.
  bool scenario_finished() const { return scenario_finished_; }
  const Setpoint& active_setpoint() const { return active_; }
  const DynamicsTerms& last_terms() const { return terms_; }

  /// Evaluates the model through `shared` (in process: the estimator and
  /// the filter evaluate it at the same estimates). std::invalid_argument
  /// when its parameters are not this controller's; null: its own.
  void ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared);

 private:
  SetpointStatus Check(const Setpoint& setpoint) const;

  PlatformParams platform_;
  std::shared_ptr<SharedDynamicsTerms> shared_terms_;
  ControllerConfig gains_;
  std::optional<Scenario> scenario_;
  Setpoint active_;
  bool rejected_ = false;
  bool scenario_finished_ = false;
  std::optional<int64_t> first_utime_;
  struct MotionClock {
    int64_t utime = 0;
    int64_t motion_time_us = 0;
    bool running = false;
  };
  std::optional<MotionClock> motion_clock_;
  bool restart_at_first_clock_ = false;
  int64_t motion_offset_us_ = 0;  ///< subtracted from the motion clock
  std::optional<int64_t> last_utime_;
  DynamicsTerms terms_{};
};

}  // namespace stewart
