#pragma once
// The controller process's decisions, without LCM: which state estimates it
// acts on, what it rejects and counts, the nominal command it publishes and
// the setpoint it echoes. The node (controller/node) converts messages and
// publishes; replay drives the same class over a recorded log.
//
// The state estimates carry the stack time: one whose time is implausible
// (common/input_time_check.h) is rejected before the control law sees it.
// OnState takes the message's receive time (wall clock, us) from the live
// node, nullopt in replay; it only widens the window after a gap and never
// reaches the control law, whose time is the state's.
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>

#include "stewart/common/health_counters.h"
#include "stewart/common/input_time_check.h"
#include "stewart/common/resend_answer.h"
#include "stewart/common/signals.h"
#include "stewart/controller/controller.h"

namespace stewart {

/// The setpoint a scenario-following controller tracked for one state.
struct SetpointEcho {
  int64_t utime = 0;
  int64_t seq = 0;
  int64_t sample_utime = 0;
  Setpoint setpoint;
};

/// What one state estimate produced.
struct ControllerProcessOutput {
  ForceCommand command;  ///< the nominal command F_des
  bool has_setpoint_echo = false;
  SetpointEcho setpoint_echo;  ///< when following a scenario
};

/// Why a state estimate produced no command (kPublished when it did).
enum class ControllerVerdict { kPublished, kStateNotUsable, kStepRejected, kTimeImplausible };

class ControllerProcess {
 public:
  /// `counters` must outlive this object; `time`: lcm.time_window_s,
  /// lcm.max_time_rate. A stream of states rejected whole for longer than
  /// gains.stale_age_s is a FAULT.
  ControllerProcess(const PlatformParams& platform, const ControllerConfig& gains,
                    const Vector6d& home_pose, std::optional<Scenario> scenario,
                    HealthCounters* counters, const TimePlausibilityParams& time = {});

  /// A state estimate arrived: kPublished fills `out`. The state answered
  /// last, received again (a lockstep resend: an answer was lost
  /// downstream), is answered again with the same command and setpoint echo,
  /// without a second control step (common/resend_answer.h; counted
  /// `resends_answered`).
  ControllerVerdict OnState(const StateSample& state, ControllerProcessOutput* out,
                            std::optional<int64_t> receive_wall_us = std::nullopt);
  /// A live setpoint arrived (only without a scenario).
  void OnSetpoint(const Setpoint& setpoint);
  /// The supervisor's state arrived: its motion clock (Controller::SetMotionClock).
  void OnSupervisor(int64_t utime, int64_t motion_time_us, bool running);
  /// The scenario starts over at this process's first supervisor state.
  void RestartScenario() { controller_.RestartScenarioAtFirstMotionClock(); }

  const Controller& controller() const { return controller_; }
  /// Controller::ShareModelTerms.
  void ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared) {
    controller_.ShareModelTerms(std::move(shared));
  }

 private:
  Controller controller_;
  HealthCounters* counters_;
  InputTimeCheck time_check_;
  ResendAnswer resend_;
  ControllerProcessOutput last_answer_;  ///< the answer to the state resend_ holds
  int64_t command_seq_ = 0;
  int64_t setpoint_seq_ = 0;
};

}  // namespace stewart
