#pragma once
#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/common/health_counters.h"
#include "stewart/health_t.hpp"

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
class HealthReporter : public HealthCounters {
 public:
  HealthReporter(std::string name, std::string channel, double rate_hz);

  /// Publishes if the period elapsed (or `force`). Returns true if sent.
  bool MaybePublish(lcm::LCM* lcm, bool force = false);
  health_t Snapshot();

 private:
  std::string channel_;
  std::chrono::steady_clock::duration period_;
  std::chrono::steady_clock::time_point last_publish_{};
  int64_t seq_ = 0;
};

}  // namespace stewart
