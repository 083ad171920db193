#include "stewart/common/health_counters.h"

#include <spdlog/spdlog.h>

namespace stewart {

HealthCounters::HealthCounters(std::string name) : name_(std::move(name)) {}

int64_t& HealthCounters::Slot(const std::string& counter) {
  for (auto& entry : counters_) {
    if (entry.first == counter) return entry.second;
  }
  counters_.emplace_back(counter, 0);
  return counters_.back().second;
}

void HealthCounters::Reject(const std::string& reason, const std::string& detail) {
  ++rejected_inputs_;
  int64_t& slot = Slot("rejected_" + reason);
  ++slot;
  last_error_ = detail.empty() ? reason : reason + ": " + detail;
  // The first and then every 1000th, so a flood of bad input cannot flood the log.
  if (slot == 1 || slot % 1000 == 0) {
    spdlog::warn("{}: rejected input ({}), {} so far", name_, last_error_, slot);
  }
}

void HealthCounters::Count(const std::string& counter, int64_t increment) {
  Slot(counter) += increment;
}

void HealthCounters::SetCounter(const std::string& counter, int64_t value) {
  Slot(counter) = value;
}

int64_t HealthCounters::counter(const std::string& counter) const {
  for (const auto& entry : counters_) {
    if (entry.first == counter) return entry.second;
  }
  return 0;
}

void HealthCounters::SetState(int8_t state) {
  if (state != health_state::kFault) naming_latched_fault_ = false;
  state_ = state;
  if (health_state::Severity(state) >= health_state::Severity(worst_state_)) worst_state_ = state;
  if (state == health_state::kFault && !fault_latched_) {
    fault_latched_ = true;
    naming_latched_fault_ = true;
    latched_error_ = last_error_;
  }
}

void HealthCounters::SetError(const std::string& error) {
  last_error_ = error;
  // A node names its fault before or after entering it: while the fault
  // that latched lasts, its latest error names it.
  if (naming_latched_fault_) latched_error_ = error;
}

bool HealthCounters::AcknowledgeFault() {
  if (!fault_latched_ || state_ == health_state::kFault) return false;
  fault_latched_ = false;
  naming_latched_fault_ = false;
  latched_error_.clear();
  return true;
}

int8_t HealthCounters::TakeWorstState() {
  const int8_t worst = worst_state_;
  worst_state_ = state_;
  return worst;
}

void HealthCounters::SetStackTime(int64_t utime, int64_t sample_utime) {
  utime_ = utime;
  sample_utime_ = sample_utime;
}

}  // namespace stewart
