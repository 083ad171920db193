#pragma once
// The operator's acknowledgement of a process's latched fault
// (docs/operations.md, "Health"): an operator_command_t with COMMAND_RESET on
// lcm.channels.operator whose
//   - tag verifies under lcm.auth_key_file (MessageAuthenticator; without a
//     key every tag verifies, as every message does),
//   - utime (the operator's wall clock) is within lcm.time_window_s of the
//     receive time, and
//   - seq is newer than the last RESET accepted from that operator_id,
// so a recorded RESET played back later acknowledges nothing. Every other
// command on the channel is the supervisor's business and ignored here.
//
// NodeMain installs one listener per process; the node's loop attaches its
// receiver to it (RunNodeLoop does; a node with a loop of its own may call
// AttachOperatorResets), else it reads a socket of its own, filtered by the
// kernel to the operator channel. Every HealthReporter of the process polls
// it when it beats: a RESET acknowledges the faults at the next heartbeat,
// which shows it.
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "stewart/common/health_counters.h"
#include "stewart/guard/operator_command_check.h"
#include "stewart/node/lcm_config.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/operator_command_t.hpp"

namespace stewart {

/// What a listener decided about the RESETs it saw.
struct OperatorResetCounts {
  int64_t accepted = 0;
  int64_t rejected_auth = 0;     ///< the tag did not verify
  int64_t rejected_time = 0;     ///< utime further than the window from the receive time
  int64_t rejected_replay = 0;   ///< seq not newer than the operator's last accepted RESET
  int64_t rejected_invalid = 0;  ///< operator_id 0
};

/// The decision on one operator command, without a socket (tests, replay).
class OperatorResetFilter {
 public:
  OperatorResetFilter(MessageAuthenticator auth, double window_s);
  /// True for a RESET to accept; counts every RESET.
  bool OnCommand(const operator_command_t& msg, int64_t receive_wall_us);
  const OperatorResetCounts& counts() const { return counts_; }

 private:
  MessageAuthenticator auth_;
  OperatorCommandCheck check_;  // the actuators' rule: MAC, time window, seq per console
  OperatorResetCounts counts_;
};

/// For an actuator's own RESET (its guard's latch, plant_sim and hw_bridge):
/// whether `msg` is a RESET to act on under `check` (MAC `authentic`,
/// `wall_now_us` its receiver's wall clock). A RESET is counted in `counters`
/// as an input, and a refused one as a rejection named by its verdict; other
/// commands (the supervisor's) are not this receiver's business.
bool AcceptActuatorReset(const operator_command_t& msg, bool authentic, int64_t wall_now_us,
                         OperatorCommandCheck* check, HealthCounters* counters);

/// The process's RESETs: one OperatorResetFilter on the operator channel,
/// fed by the node's own receiver when it attaches one (no extra socket:
/// every extra socket on the bus costs the kernel a copy of every datagram),
/// else by a socket of its own, opened at the first poll.
class OperatorResets {
 public:
  /// Throws std::runtime_error for a bad key file.
  explicit OperatorResets(const LcmConfig& lcm);
  /// `receiver` (on this process's URL) takes the operator channel too.
  void Attach(LcmReceiver* receiver);
  /// Handles what arrived on the own socket (when none is attached), without
  /// waiting; the counts so far. Throws std::runtime_error when the own
  /// socket cannot join the bus.
  OperatorResetCounts Poll();

  void OnOperator(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                  const operator_command_t* msg);

 private:
  std::string url_;
  std::string channel_;
  OperatorResetFilter filter_;
  bool attached_ = false;
  std::unique_ptr<LcmReceiver> own_receiver_;
};

/// NodeMain: the process's RESETs, on `lcm`'s URL and operator channel.
void InstallOperatorResetListener(const LcmConfig& lcm);
/// A node's receiver takes the operator channel (RunNodeLoop does it): the
/// process then opens no socket of its own for it. No-op when none is
/// installed.
void AttachOperatorResets(LcmReceiver* receiver);
/// Polls the installed listener: its counts (all 0 when none is installed).
OperatorResetCounts PollOperatorResets();

}  // namespace stewart
