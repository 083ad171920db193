#include "stewart/node/health_reporter.h"

namespace stewart {

HealthReporter::HealthReporter(std::string name, std::string channel, double rate_hz)
    : HealthCounters(std::move(name)),
      channel_(std::move(channel)),
      period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(1.0 / rate_hz))) {}

health_t HealthReporter::Snapshot() {
  health_t msg;
  msg.utime = utime();
  msg.seq = seq_;
  msg.sample_utime = sample_utime();
  msg.name = name();
  msg.state = state();
  msg.messages_in = messages_in();
  msg.messages_out = messages_out();
  msg.rejected_inputs = rejected_inputs();
  msg.num_counters = static_cast<int32_t>(counters().size());
  for (const auto& entry : counters()) {
    msg.counter_names.push_back(entry.first);
    msg.counter_values.push_back(entry.second);
  }
  msg.last_error = last_error();
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
