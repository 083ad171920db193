#pragma once
// The newest value of every channel the viewer shows, in the library's own
// types (no LCM): what the LCM thread or the log player stores and what the
// frame builder reads.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "stewart/model/types.h"

namespace stewart::viewer {

/// A state estimate or the ground truth (state_t).
struct StateSample {
  bool valid = false;  ///< false until the first message
  int64_t utime_us = 0;
  Vector6d q = Vector6d::Zero();   ///< [x y z (m), phi theta psi (rad, Z-Y-X)] of {P} in {B}
  Vector6d qd = Vector6d::Zero();  ///< m/s, rad/s (Euler rates)
  int32_t status = 0;              ///< state_t.STATUS_* bits
};

struct SetpointSample {
  bool valid = false;
  int64_t utime_us = 0;
  Vector6d q_des = Vector6d::Zero();
};

/// A leg force command (force_command_t), nominal or safe.
struct ForceSample {
  bool valid = false;
  int64_t utime_us = 0;
  std::array<double, 6> force_n{};
  int32_t flags = 0;  ///< force_command_t.FLAG_* bits
};

/// One barrier of the filter: its value and its Log-Sum-Exp weight.
struct BarrierSample {
  std::string name;
  double h = 0.0;
  double weight = 0.0;
};

/// The parts of safety_diagnostics_t the page shows.
struct DiagnosticsSample {
  bool valid = false;
  int64_t utime_us = 0;
  int active_case = 0;  ///< safety_diagnostics_t.CASE_*
  std::vector<BarrierSample> position, velocity;
  double h_pos = 0.0, h_vel = 0.0;
  double correction_norm_n = 0.0;  ///< ||F* - F_des||
  int32_t flags = 0;
  double compute_us = 0.0;
};

/// One process's newest heartbeat (health_t).
struct HealthSample {
  std::string name;
  int64_t utime_us = 0;
  int state = 0;
  int worst_state = 0;
  bool fault_latched = false;
  std::string last_error;
  int64_t messages_in = 0;
  int64_t rejected_inputs = 0;
  /// plant_sim's loop latency (its `latency_p99_us` counter); < 0 when absent.
  double latency_p99_us = -1.0;
  int64_t missed_ticks = -1;  ///< plant_sim's `missed_ticks` counter; < 0 when absent
};

struct SupervisorSample {
  bool valid = false;
  int64_t utime_us = 0;
  int state = 0;  ///< supervisor_state_t.STATE_*
  double arming_progress = 0.0;
  int64_t motion_time_us = 0;
  std::string reason;
  bool fault_latched = false;
  int64_t last_operator_id = 0;
  int64_t last_operator_seq = 0;
  std::string last_operator_reply;
};

/// The newest operator command on the bus (operator_command_t), live only:
/// its utime is the console's wall clock, which a log index by stack time
/// cannot place (the supervisor's state carries the last one it judged).
struct OperatorSample {
  bool valid = false;
  int64_t operator_id = 0;
  int64_t seq = 0;
  int command = 0;  ///< operator_command_t.COMMAND_*
  std::string note;
  bool authentic = false;  ///< its MAC verified under the run's key (true without one)
};

struct ViewerSnapshot {
  StateSample estimate;
  StateSample truth;
  SetpointSample setpoint;
  ForceSample nominal;
  ForceSample safe;
  DiagnosticsSample diagnostics;
  SupervisorSample supervisor;
  OperatorSample last_operator_command;
  std::map<std::string, HealthSample> health;  ///< by process name
};

}  // namespace stewart::viewer
