#pragma once
#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <utility>
#include <vector>

#include "stewart/health_t.hpp"

namespace stewart {

/// Counts a process's traffic and rejections and publishes health_t as a
/// heartbeat. The heartbeat is paced by the wall clock (it must keep beating
/// when inputs stop); the utime it carries is the stack time of the newest
/// processed input, so logs replay consistently.
class HealthReporter {
 public:
  HealthReporter(std::string name, std::string channel, double rate_hz);

  void CountIn() { ++messages_in_; }
  void CountOut() { ++messages_out_; }
  /// A rejected input: counts it under `reason` and in rejected_inputs.
  void Reject(const std::string& reason, const std::string& detail = "");
  /// A process-specific counter (not a rejection).
  void Count(const std::string& counter, int64_t increment = 1);
  void SetCounter(const std::string& counter, int64_t value);
  int64_t counter(const std::string& counter) const;
  int64_t rejected_inputs() const { return rejected_inputs_; }

  void SetState(int8_t state) { state_ = state; }
  void SetError(const std::string& error) { last_error_ = error; }
  void SetStackTime(int64_t utime, int64_t sample_utime);

  /// Publishes if the period elapsed (or `force`). Returns true if sent.
  bool MaybePublish(lcm::LCM* lcm, bool force = false);
  health_t Snapshot();

 private:
  int64_t& Slot(const std::string& counter);

  std::string name_;
  std::string channel_;
  std::chrono::steady_clock::duration period_;
  std::chrono::steady_clock::time_point last_publish_{};
  int64_t seq_ = 0;
  int64_t utime_ = 0;
  int64_t sample_utime_ = 0;
  int8_t state_ = health_t::STATE_STARTING;
  int64_t messages_in_ = 0;
  int64_t messages_out_ = 0;
  int64_t rejected_inputs_ = 0;
  std::vector<std::pair<std::string, int64_t>> counters_;
  std::string last_error_;
};

}  // namespace stewart
