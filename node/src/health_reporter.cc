#include "stewart/node/health_reporter.h"

#include <spdlog/spdlog.h>

namespace stewart {

HealthReporter::HealthReporter(std::string name, std::string channel, double rate_hz)
    : HealthCounters(std::move(name)),
      channel_(std::move(channel)),
      period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(1.0 / rate_hz))),
      reset_source_(PollOperatorResets) {}

void HealthReporter::TakeAcknowledgements() {
  const OperatorResetCounts counts = reset_source_ ? reset_source_() : OperatorResetCounts{};
  // The counts appear once there was something to count, so a heartbeat
  // without operator traffic keeps its counter list.
  if (counts.accepted > 0) SetCounter("operator_resets", counts.accepted);
  const int64_t rejected = counts.rejected_auth + counts.rejected_time + counts.rejected_replay +
                           counts.rejected_invalid;
  if (rejected > 0) SetCounter("operator_resets_rejected", rejected);
  if (counts.accepted <= resets_seen_) return;
  resets_seen_ = counts.accepted;
  if (AcknowledgeFault()) {
    spdlog::info("{}: latched fault acknowledged by an operator RESET", name());
  } else if (fault_latched()) {
    spdlog::warn("{}: operator RESET while still in FAULT ({}): the fault stays latched", name(),
                 last_error());
  }
}

health_t HealthReporter::Snapshot() {
  TakeAcknowledgements();
  const auto now = std::chrono::steady_clock::now();
  health_t msg;
  msg.utime = utime();
  msg.seq = seq_;
  msg.sample_utime = sample_utime();
  msg.name = name();
  msg.state = state();
  msg.worst_state = TakeWorstState();
  msg.fault_latched = fault_latched();
  msg.latched_error = latched_error();
  msg.messages_in = messages_in();
  msg.messages_out = messages_out();
  msg.rejected_inputs = rejected_inputs();
  msg.period_us =
      seq_ == 0
          ? 0
          : std::chrono::duration_cast<std::chrono::microseconds>(now - last_snapshot_).count();
  msg.messages_in_delta = messages_in() - previous_messages_in_;
  msg.messages_out_delta = messages_out() - previous_messages_out_;
  msg.rejected_inputs_delta = rejected_inputs() - previous_rejected_inputs_;
  msg.num_counters = static_cast<int32_t>(counters().size());
  previous_counter_values_.resize(counters().size(), 0);  // a new counter: from 0
  for (size_t i = 0; i < counters().size(); ++i) {
    msg.counter_names.push_back(counters()[i].first);
    msg.counter_values.push_back(counters()[i].second);
    msg.counter_deltas.push_back(counters()[i].second - previous_counter_values_[i]);
    previous_counter_values_[i] = counters()[i].second;
  }
  msg.last_error = last_error();
  previous_messages_in_ = messages_in();
  previous_messages_out_ = messages_out();
  previous_rejected_inputs_ = rejected_inputs();
  last_snapshot_ = now;
  ++seq_;
  return msg;
}

bool HealthReporter::MaybePublish(lcm::LCM* lcm, bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_publish_ < period_) return false;
  last_publish_ = now;
  const health_t msg = Snapshot();
  lcm->publish(channel_, &msg);
  return true;
}

}  // namespace stewart
