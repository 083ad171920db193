#include "stewart/node/health_reporter.h"

#include <spdlog/spdlog.h>

namespace stewart {

HealthReporter::HealthReporter(std::string name, std::string channel, double rate_hz)
    : name_(std::move(name)),
      channel_(std::move(channel)),
      period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(1.0 / rate_hz))) {}

int64_t& HealthReporter::Slot(const std::string& counter) {
  for (auto& entry : counters_) {
    if (entry.first == counter) return entry.second;
  }
  counters_.emplace_back(counter, 0);
  return counters_.back().second;
}

void HealthReporter::Reject(const std::string& reason, const std::string& detail) {
  ++rejected_inputs_;
  int64_t& slot = Slot("rejected_" + reason);
  ++slot;
  last_error_ = detail.empty() ? reason : reason + ": " + detail;
  // Log the first and then every 1000th, so a flood of bad input cannot
  // flood the log.
  if (slot == 1 || slot % 1000 == 0) {
    spdlog::warn("{}: rejected input ({}), {} so far", name_, last_error_, slot);
  }
}

void HealthReporter::Count(const std::string& counter, int64_t increment) {
  Slot(counter) += increment;
}

void HealthReporter::SetCounter(const std::string& counter, int64_t value) {
  Slot(counter) = value;
}

int64_t HealthReporter::counter(const std::string& counter) const {
  for (const auto& entry : counters_) {
    if (entry.first == counter) return entry.second;
  }
  return 0;
}

void HealthReporter::SetStackTime(int64_t utime, int64_t sample_utime) {
  utime_ = utime;
  sample_utime_ = sample_utime;
}

health_t HealthReporter::Snapshot() {
  health_t msg;
  msg.utime = utime_;
  msg.seq = seq_;
  msg.sample_utime = sample_utime_;
  msg.name = name_;
  msg.state = state_;
  msg.messages_in = messages_in_;
  msg.messages_out = messages_out_;
  msg.rejected_inputs = rejected_inputs_;
  msg.num_counters = static_cast<int32_t>(counters_.size());
  for (const auto& entry : counters_) {
    msg.counter_names.push_back(entry.first);
    msg.counter_values.push_back(entry.second);
  }
  msg.last_error = last_error_;
  return msg;
}

bool HealthReporter::MaybePublish(lcm::LCM* lcm, bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_publish_ < period_) return false;
  last_publish_ = now;
  const health_t msg = Snapshot();
  ++seq_;
  lcm->publish(channel_, &msg);
  return true;
}

}  // namespace stewart
