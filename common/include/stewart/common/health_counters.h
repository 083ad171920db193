#pragma once
// What a process counts about itself: inputs, outputs, rejections by reason,
// its own counters, its state and last error. LCM-free, so the library class
// that makes a process's decisions counts here, and the node publishes the
// counts as its heartbeat (node/health_reporter.h). Replay and the in-process
// closed loop give the same classes a HealthCounters of their own.
//
// The state a heartbeat carries must not depend on when it is sampled: a
// heartbeat goes out a few times a second, a process changes state per
// message. So besides the current state this keeps the worst state since
// the last report (TakeWorstState, once per heartbeat) and latches a FAULT
// until it is acknowledged (AcknowledgeFault: an operator's RESET).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace stewart {

/// The process states, as health_t.state carries them.
namespace health_state {
constexpr int8_t kStarting = 0;
constexpr int8_t kOk = 1;
constexpr int8_t kDegraded = 2;
constexpr int8_t kFault = 3;
constexpr int8_t kStopped = 4;

/// How bad a state is: FAULT 2, DEGRADED 1, the others (starting, ok,
/// stopped: a life-cycle stage, not a problem) 0.
constexpr int Severity(int8_t state) { return state == kFault ? 2 : state == kDegraded ? 1 : 0; }
}  // namespace health_state

class HealthCounters {
 public:
  explicit HealthCounters(std::string name);

  void CountIn() { ++messages_in_; }
  void CountOut() { ++messages_out_; }
  /// A rejected input: counts it under "rejected_<reason>" and in
  /// rejected_inputs; logs the first and every 1000th of each reason.
  void Reject(const std::string& reason, const std::string& detail = "");
  /// A process-specific counter (not a rejection).
  void Count(const std::string& counter, int64_t increment = 1);
  void SetCounter(const std::string& counter, int64_t value);
  int64_t counter(const std::string& counter) const;

  /// The current state. A FAULT latches (fault_latched) until acknowledged;
  /// any state counts towards the worst state since the last report.
  void SetState(int8_t state);
  void SetError(const std::string& error);
  /// An operator acknowledged the latched fault: the latch clears unless
  /// the process is in FAULT now (a reset cannot clear a fault that
  /// persists). Returns true when a latched fault was cleared.
  bool AcknowledgeFault();
  /// The worst state (health_state::Severity; ties: the later) since the
  /// previous call, the current one included; starts the next period at the
  /// current state. Once per heartbeat.
  int8_t TakeWorstState();
  /// The stack time of the newest processed input (utime of the message and
  /// of the sensor sample it derives from).
  void SetStackTime(int64_t utime, int64_t sample_utime);

  const std::string& name() const { return name_; }
  int8_t state() const { return state_; }
  int64_t messages_in() const { return messages_in_; }
  int64_t messages_out() const { return messages_out_; }
  int64_t rejected_inputs() const { return rejected_inputs_; }
  int64_t utime() const { return utime_; }
  int64_t sample_utime() const { return sample_utime_; }
  const std::string& last_error() const { return last_error_; }
  /// A FAULT happened since start or the last acknowledgement.
  bool fault_latched() const { return fault_latched_; }
  /// What the latched FAULT was: last_error when it was entered, or the
  /// error set while it lasted.
  const std::string& latched_error() const { return latched_error_; }
  /// The worst state since the last TakeWorstState, without starting a new period.
  int8_t worst_state() const { return worst_state_; }
  /// Every counter in the order first counted.
  const std::vector<std::pair<std::string, int64_t>>& counters() const { return counters_; }

 private:
  int64_t& Slot(const std::string& counter);

  std::string name_;
  int64_t utime_ = 0;
  int64_t sample_utime_ = 0;
  int8_t state_ = health_state::kStarting;
  int8_t worst_state_ = health_state::kStarting;
  bool fault_latched_ = false;
  bool naming_latched_fault_ = false;  ///< in the FAULT that latched: SetError names it
  std::string latched_error_;
  int64_t messages_in_ = 0;
  int64_t messages_out_ = 0;
  int64_t rejected_inputs_ = 0;
  std::vector<std::pair<std::string, int64_t>> counters_;
  std::string last_error_;
};

}  // namespace stewart
