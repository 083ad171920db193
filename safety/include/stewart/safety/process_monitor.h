#pragma once
// Which of the stack's processes are alive and healthy, from their
// heartbeats (health_t), for the supervisor: a required process that reports
// FAULT, restarts (its heartbeat sequence starts over) or goes silent is a
// fault; arming needs every required process healthy. No LCM: the node
// passes each heartbeat and its wall receive time in.
#include <cstdint>
#include <string>
#include <vector>

namespace stewart::safety {

class ProcessMonitor {
 public:
  /// `required`: process names, alternatives separated by '|' (one of
  /// plant_sim or hw_bridge). `timeout_us`: a heartbeat older than this is
  /// silence.
  ProcessMonitor(const std::vector<std::string>& required, int64_t timeout_us);

  /// A heartbeat from `name` (health_t state, seq) received at `wall_us`.
  /// Returns a fault description when it shows one ("" otherwise): the
  /// process reported FAULT, or restarted (seq went back) after having been
  /// seen. Heartbeats of processes that are not required are ignored.
  std::string OnHeartbeat(const std::string& name, int8_t state, int64_t seq, int64_t wall_us);

  /// Whether the supervisor lets the platform move (ARMING or ARMED), as of
  /// `wall_us`. A platform can move before every required process has been
  /// heard from (auto_arm does not wait for heartbeats, and a heartbeat can
  /// be missed while the receiver starts): see CheckSilence.
  void SetMoving(bool moving, int64_t wall_us);

  /// Silence check at `wall_us`: a fault description for each required
  /// process seen before whose heartbeat is older than the timeout, and for
  /// each requirement none of whose processes was ever heard from once the
  /// platform has been moving for the timeout (each reported once per
  /// silence).
  std::vector<std::string> CheckSilence(int64_t wall_us);

  /// Every required process (one of each alternative) sent a recent
  /// heartbeat with state OK or DEGRADED. Else false and `why_not` names
  /// the first that did not.
  bool Healthy(int64_t wall_us, std::string* why_not) const;

 private:
  struct Process {
    std::string name;
    size_t group = 0;  ///< index of its requirement (alternatives share one)
    bool seen = false;
    bool silent_reported = false;
    int8_t state = 0;
    int64_t seq = -1;
    int64_t wall_us = 0;
  };
  std::vector<Process> processes_;
  size_t groups_ = 0;
  int64_t timeout_us_;
  bool moving_ = false;
  int64_t moving_since_us_ = 0;
  std::vector<bool> unheard_reported_;  // per requirement, while moving
};

}  // namespace stewart::safety
