#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "stewart/common/health_counters.h"
#include "stewart/health_t.hpp"
#include "stewart/node/operator_reset.h"

namespace stewart {

static_assert(health_state::kStarting == health_t::STATE_STARTING &&
                  health_state::kOk == health_t::STATE_OK &&
                  health_state::kDegraded == health_t::STATE_DEGRADED &&
                  health_state::kFault == health_t::STATE_FAULT &&
                  health_state::kStopped == health_t::STATE_STOPPED,
              "health_state and health_t.STATE_* must agree");

/// A process's HealthCounters published as health_t, the heartbeat. The
/// heartbeat is paced by the wall clock (it must keep beating when inputs
/// stop); the utime it carries is the stack time of the newest processed
/// input, so logs replay consistently.
///
/// Each heartbeat carries the current state and the worst since the previous
/// heartbeat (a DEGRADED or FAULT between two heartbeats is never missed),
/// the latched fault, and every count both since start and since the previous
/// heartbeat. Before it beats it takes the operator's RESETs (operator_reset.h)
/// that arrived since: each acknowledges the latched fault.
class HealthReporter : public HealthCounters {
 public:
  HealthReporter(std::string name, std::string channel, double rate_hz);

  /// Where acknowledgements come from: a function returning how many RESETs
  /// were accepted since start. Default: the process's listener
  /// (PollOperatorResets). Tests give their own.
  using ResetSource = std::function<OperatorResetCounts()>;
  void SetResetSource(ResetSource source) { reset_source_ = std::move(source); }

  /// Publishes if the period elapsed (or `force`). Returns true if sent.
  bool MaybePublish(lcm::LCM* lcm, bool force = false);
  /// The next heartbeat, and starts the next period of the "since the
  /// previous heartbeat" fields (the worst state, the deltas).
  health_t Snapshot();

 private:
  /// Takes the RESETs accepted since the last call: acknowledges the fault.
  void TakeAcknowledgements();

  std::string channel_;
  std::chrono::steady_clock::duration period_;
  std::chrono::steady_clock::time_point last_publish_{};
  std::chrono::steady_clock::time_point last_snapshot_{};
  int64_t seq_ = 0;
  ResetSource reset_source_;
  int64_t resets_seen_ = 0;
  // The totals in the previous heartbeat, for its deltas.
  int64_t previous_messages_in_ = 0;
  int64_t previous_messages_out_ = 0;
  int64_t previous_rejected_inputs_ = 0;
  std::vector<int64_t> previous_counter_values_;  // by counters() index: counters only append
};

}  // namespace stewart
