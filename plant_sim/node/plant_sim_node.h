#pragma once
// The plant_sim process: the simulated platform on LCM (docs/simulation.md).
// Publishes sensor_t and the ground-truth state_t at every tick, health_t as
// a heartbeat, and applies force_command_t from the safety filter: only the
// announced safety session's (supervisor_state_t; CommandGate), and only
// while its own guard on its own readings is not tripped (ActuatorGuard,
// cleared by an operator RESET on operator_command_t).
#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/force_command_t.hpp"
#include "stewart/guard/actuator_guard.h"
#include "stewart/guard/operator_command_check.h"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/latency_histogram.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/plant_sim/command_gate.h"
#include "stewart/plant_sim/command_policy.h"
#include "stewart/plant_sim/disturbance_source.h"
#include "stewart/plant_sim/loop_latency_tracker.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"
#include "stewart/plant_sim/tick_accounting.h"
#include "stewart/plant_sim/truth.h"
#include "stewart/sensor_t.hpp"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {

enum class SimMode { kRealTime, kLockstep };

struct PlantSimOptions {
  SimMode mode = SimMode::kRealTime;
  double duration_s = 0.0;  ///< simulated seconds; 0 = until SIGINT/SIGTERM
  /// utime of tick 0 (us); < 0 = wall clock (real time) or 0 (lockstep).
  int64_t start_utime = -1;
  /// Lockstep: re-sends tick 0's sample at this wall period until it is
  /// answered, for a stack that subscribes after plant_sim started. 0 = never.
  double startup_republish_s = 0.25;
};

class PlantSimNode {
 public:
  /// `truth`: the plant's physics; the stack's config for everything else
  /// (rate, channels, integrator, timeouts).
  PlantSimNode(const StackConfig& config, const PlantTruth& truth, lcm::LCM* lcm,
               const PlantSimOptions& options);
  /// Runs to the end of the duration or a stop signal: kOk, kLockstepTimeout
  /// or kIntegrationFailure.
  ExitCode Run();

 private:
  ExitCode RunRealTime();
  ExitCode RunLockstep();
  void PublishSample();
  void ApplyRealTimeDecision();
  void AdvanceTick();
  void HandleCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                     const force_command_t* msg);
  void HandleSupervisor(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                        const supervisor_state_t* msg);
  void HandleOperator(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                      const operator_command_t* msg);
  /// The guard's verdict on the readings of the sample just published.
  void CheckGuard(const Vector6d& leg_length_m);
  /// health state and error: the guard's FAULT first, then the fallback.
  void UpdateHealthState();
  void UpdateTrustCounters();
  void UpdateLatencyCounters();
  void UpdateTickCounters();

  StackConfig config_;
  PlantSimOptions options_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  Plant plant_;
  SensorModel sensors_;
  DisturbanceSource disturbance_;
  HealthReporter health_;
  RealTimeCommandHold hold_;
  MessageAuthenticator auth_;
  ActuatorGuard guard_;
  OperatorCommandCheck operator_check_;
  std::string guard_error_;         // the health error while the guard is tripped
  int64_t applied_age_max_us_ = 0;  // oldest command applied at a tick (us of stack time)
  int64_t period_us_ = 1000;
  int64_t utime0_ = 0;
  int64_t tick_ = 0;        // index of the newest published sample
  int64_t tick_utime_ = 0;  // its utime
  bool fallback_active_ = false;
  sensor_t last_sensor_{};
  /// Lockstep: the period before the next sample applied the answer to the
  /// sample before it (sensor_t::STATUS_ANSWER_APPLIED).
  bool answer_applied_ = false;
  CommandGate gate_;
  LoopLatencyTracker latency_tracker_;
  TickAccounting tick_accounting_;
  LatencyHistogram latency_;
  LatencyHistogram tick_jitter_;  // real time: tick start after its deadline
};

}  // namespace stewart
