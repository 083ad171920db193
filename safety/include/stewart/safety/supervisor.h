#pragma once
// The supervisor: whether the platform may move, and how (docs/operations.md,
// "Arming and e-stop"). The safety filter keeps a moving platform inside its
// limits; the supervisor decides whether it moves at all. A state machine
// without LCM, run inside the safety process (SafetyProcess applies its mode
// to every command), so replay and the in-process loop decide as the
// process does.
//
//   DISARMED  power-on: actuators off, the lead screws hold the legs.
//   ARMING    a ramp from the hold to the filtered command:
//             F = (1 - a) F_hold + a F*, a = 0 -> 1 over arming_ramp_s of
//             stack time. Both ends satisfy the CBF conditions, which are
//             linear in F, so every blend does.
//   ARMED     the filtered command F*.
//   HOLD      the safe stop (gravity-compensating brake to rest) for
//             hold_brake_s, then the actuators off (the lead screws hold),
//             latched: entered on any fault while ARMING or ARMED, or on an
//             operator hold. Left only by an operator resume (after a reset
//             when a fault caused it), through ARMING.
//   ESTOP     actuators off, latched: left only by a reset (to DISARMED).
//
// Nothing resumes by itself: a restarted process, a lost heartbeat or a
// controller that went quiet hold the platform until an operator resumes.
// Decisions that depend on time use stack time (the state estimate's
// utime); the faults the node detects from heartbeats and the operator's
// commands are inputs.
#include <cstdint>
#include <string>
#include <vector>

#include "stewart/common/enum_table.h"

namespace stewart::safety {

enum class SupervisorState : int8_t {
  kDisarmed = 0,
  kArming = 1,
  kArmed = 2,
  kHold = 3,
  kEstop = 4
};
inline constexpr EnumTable<SupervisorState, 5> kSupervisorStateNames{{{
    {SupervisorState::kDisarmed, "DISARMED"},
    {SupervisorState::kArming, "ARMING"},
    {SupervisorState::kArmed, "ARMED"},
    {SupervisorState::kHold, "HOLD"},
    {SupervisorState::kEstop, "ESTOP"},
}}};
inline const char* ToString(SupervisorState s) { return kSupervisorStateNames.Name(s).data(); }

enum class OperatorCommand : int8_t {
  kArm = 1,
  kHold = 2,
  kResume = 3,
  kEstop = 4,
  kReset = 5,
  kHeartbeat = 6,
};
inline constexpr EnumTable<OperatorCommand, 6> kOperatorCommandNames{{{
    {OperatorCommand::kArm, "arm"},
    {OperatorCommand::kHold, "hold"},
    {OperatorCommand::kResume, "resume"},
    {OperatorCommand::kEstop, "estop"},
    {OperatorCommand::kReset, "reset"},
    {OperatorCommand::kHeartbeat, "heartbeat"},
}}};
inline const char* ToString(OperatorCommand c) { return kOperatorCommandNames.Name(c).data(); }

/// The `supervisor` config section.
struct SupervisorConfig {
  /// Stack time of the ramp from the hold to the filtered command (s), on
  /// arming and on resuming.
  double arming_ramp_s = 1.0;
  /// While moving, fallbacks (no fresh nominal command, or a state that is
  /// not usable) for this long (stack time, s) latch HOLD. Shorter gaps get
  /// the fallback (the safe stop) for their steps and go on: a late message
  /// on a loaded host is not a fault an operator must clear.
  double fallback_latch_s = 0.1;
  /// HOLD brakes with the safe stop for hold_brake_s (stack time, s), then
  /// turns the drive off: the lead screws hold the legs, which needs neither
  /// the model nor the estimate. The brake alone, against a model error it
  /// cannot see, let a platform 90 % heavier than the model creep 0.3 m in
  /// 40 s of HOLD. false: brake for as long as HOLD lasts (legs that do not
  /// self-lock).
  bool hold_drive_off = true;
  double hold_brake_s = 0.5;
  /// Arm by itself at the first filtered step that allows arming (a usable
  /// state the limits allow arming at and a fresh nominal command): simulation's
  /// stand-in for the operator. Never on hardware (tools/launch.sh sets it
  /// in simulation only).
  bool auto_arm = false;
  /// A state or nominal command read later than fallback_latch_s (wall
  /// time, at least kMinInputWait_s) after it arrived is a fault while
  /// moving: the safety process stalled (InputWaitFault). false where the
  /// plant waits for the stack (lockstep simulation: tools/launch.sh sets it
  /// there), since nothing moves while it waits and a loaded host would end
  /// the run in HOLD.
  bool stall_check = true;
  /// Process heartbeats older than this (wall time, s) are a fault while
  /// armed, and block arming.
  double heartbeat_timeout_s = 1.5;
  /// Dead-man: without an operator command or heartbeat for this long
  /// (wall time, s) an armed platform holds. 0 = off.
  double operator_timeout_s = 0.0;
  /// Operator commands whose utime is further than this from the
  /// receiver's wall clock (s) are rejected (replayed or delayed).
  double operator_time_window_s = 2.0;
  /// The processes that must report healthy heartbeats before an operator
  /// may arm; alternatives separated by '|' (plant_sim|hw_bridge).
  std::vector<std::string> required_processes = {"estimator", "controller", "plant_sim|hw_bridge"};
};

/// What the safety process does with its command at this step.
struct SupervisorMode {
  SupervisorState state = SupervisorState::kDisarmed;
  /// ARMING: the filtered command's share in the blend, 0..1 (1 when
  /// ARMED, 0 otherwise).
  double blend = 0.0;
  /// HOLD after its brake (SupervisorConfig::hold_drive_off): the legs held.
  bool hold_locked = false;
  bool drive_off() const {
    return state == SupervisorState::kDisarmed || state == SupervisorState::kEstop || hold_locked;
  }
};

/// What the supervisor saw at one step of the safety process.
struct SupervisorStep {
  int64_t utime = 0;          ///< stack time of the state (us)
  int64_t sample_utime = 0;   ///< its sensor sample
  bool state_usable = false;  ///< estimator converged, not diverged
  /// The state is inside every limit of the filter, or outside only position
  /// limits whose recovery barriers steer it back (velocities inside theirs).
  bool limits_allow_arming = false;
  bool filtered = false;  ///< a fresh nominal command was filtered (not a fallback)
};

class Supervisor {
 public:
  explicit Supervisor(const SupervisorConfig& config);

  /// One step of the safety process: advances the ramp and the motion
  /// clock, arms by itself when configured, and turns fallbacks while
  /// ARMING or ARMED that last fallback_latch_s into a latched HOLD.
  /// Returns this step's mode.
  SupervisorMode OnStep(const SupervisorStep& step);

  /// An operator command (already authenticated and checked for
  /// freshness). `processes_healthy` and `why_not` from the node's
  /// heartbeat monitor (arm and resume need it). Returns false, with the
  /// reason in `rejection`, when the command is not allowed now.
  bool OnOperator(OperatorCommand command, bool processes_healthy, const std::string& why_not,
                  std::string* rejection);

  /// A fault from outside the filter (a process reported FAULT, restarted,
  /// or went silent; the operator's dead-man). Latches HOLD when ARMING or
  /// ARMED; remembered as the unacknowledged fault in any state.
  void OnFault(const std::string& reason);
  /// OnFault calls since start, and the latest one's reason ("" before any).
  int64_t faults_received() const { return faults_received_; }
  const std::string& last_fault_received() const { return last_fault_received_; }

  /// The fault of a safety process that did not run: the state it reads now
  /// arrived `waited_us` (wall time) ago. While ARMING or ARMED a wait
  /// beyond fallback_latch_s is one (the actuators got no command from it
  /// for that long, as when fallbacks last that long), else none: "" when
  /// none, its reason for OnFault otherwise. Checked before the state is
  /// answered, so a process stopped and continued answers its backlog held.
  /// The wait allowed is never below kMinInputWait_s: fallback_latch_s 0
  /// (latch every fallback at once) must not make a scheduling delay of a
  /// few microseconds a fault.
  std::string InputWaitFault(int64_t waited_us) const;
  static constexpr double kMinInputWait_s = 0.1;

  SupervisorState state() const { return state_; }
  const std::string& reason() const { return reason_; }
  /// A fault not yet acknowledged by a reset.
  bool fault_latched() const { return fault_latched_; }
  double blend() const;
  /// Stack time spent ARMING or ARMED since the first arm (us).
  int64_t motion_time_us() const { return motion_time_us_; }
  int64_t transitions() const { return transitions_; }
  /// Stack time of the latest step (us).
  int64_t utime() const { return last_utime_; }
  int64_t sample_utime() const { return last_sample_utime_; }
  const SupervisorConfig& config() const { return config_; }

 private:
  void Enter(SupervisorState next, const std::string& reason);
  /// Why arming (or resuming) is not allowed at the latest step ("" = allowed).
  std::string ArmBlocker() const;

  SupervisorConfig config_;
  SupervisorState state_ = SupervisorState::kDisarmed;
  std::string reason_ = "power-on";
  bool fault_latched_ = false;
  int64_t ramp_start_utime_ = -1;  ///< -1: the ramp starts at the next step
  int64_t last_utime_ = -1;
  int64_t last_sample_utime_ = 0;
  int64_t motion_time_us_ = 0;
  int64_t fallback_since_utime_ = -1;  ///< first step of the current run of fallbacks
  int64_t hold_since_utime_ = -1;      ///< first step in the current HOLD (-1: none yet)
  int64_t transitions_ = 0;
  int64_t faults_received_ = 0;
  std::string last_fault_received_;
  double blend_ = 0.0;
  SupervisorStep last_step_{};
  bool has_step_ = false;
};

}  // namespace stewart::safety
