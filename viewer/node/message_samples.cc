#include "message_samples.h"

#include <algorithm>

namespace stewart::viewer {
namespace {

std::vector<BarrierSample> Barriers(int32_t count, const std::vector<std::string>& names,
                                    const std::vector<double>& h, const std::vector<double>& w) {
  // A malformed message (count beyond its arrays) is shown short, not read past.
  const auto n = static_cast<std::size_t>(std::max<int32_t>(0, count));
  std::vector<BarrierSample> out;
  for (std::size_t i = 0; i < n && i < names.size() && i < h.size() && i < w.size(); ++i) {
    out.push_back({names[i], h[i], w[i]});
  }
  return out;
}

}  // namespace

StateSample ToSample(const state_t& msg) {
  StateSample s;
  s.valid = true;
  s.utime_us = msg.utime;
  for (int i = 0; i < 6; ++i) {
    s.q(i) = msg.q[i];
    s.qd(i) = msg.qd[i];
  }
  s.status = msg.status;
  return s;
}

SetpointSample ToSample(const setpoint_t& msg) {
  SetpointSample s;
  s.valid = true;
  s.utime_us = msg.utime;
  for (int i = 0; i < 6; ++i) s.q_des(i) = msg.q_des[i];
  return s;
}

ForceSample ToSample(const force_command_t& msg) {
  ForceSample s;
  s.valid = true;
  s.utime_us = msg.utime;
  std::copy(std::begin(msg.force_n), std::end(msg.force_n), s.force_n.begin());
  s.flags = msg.flags;
  return s;
}

DiagnosticsSample ToSample(const safety_diagnostics_t& msg) {
  DiagnosticsSample s;
  s.valid = true;
  s.utime_us = msg.utime;
  s.active_case = msg.active_case;
  s.position = Barriers(msg.num_position, msg.position_names, msg.h_position, msg.w_position);
  s.velocity = Barriers(msg.num_velocity, msg.velocity_names, msg.h_velocity, msg.w_velocity);
  s.h_pos = msg.h_pos;
  s.h_vel = msg.h_vel;
  s.correction_norm_n = msg.correction_norm;
  s.flags = msg.flags;
  s.compute_us = static_cast<double>(msg.compute_ns) * 1e-3;
  return s;
}

HealthSample ToSample(const health_t& msg) {
  HealthSample s;
  s.name = msg.name;
  s.utime_us = msg.utime;
  s.state = msg.state;
  s.worst_state = msg.worst_state;
  s.fault_latched = msg.fault_latched;
  s.last_error = msg.last_error;
  s.messages_in = msg.messages_in;
  s.rejected_inputs = msg.rejected_inputs;
  const auto n = static_cast<std::size_t>(std::max<int32_t>(0, msg.num_counters));
  for (std::size_t i = 0; i < n && i < msg.counter_names.size() && i < msg.counter_values.size();
       ++i) {
    if (msg.counter_names[i] == "latency_p99_us") {
      s.latency_p99_us = static_cast<double>(msg.counter_values[i]);
    } else if (msg.counter_names[i] == "missed_ticks") {
      s.missed_ticks = msg.counter_values[i];
    }
  }
  return s;
}

SupervisorSample ToSample(const supervisor_state_t& msg) {
  SupervisorSample s;
  s.valid = true;
  s.utime_us = msg.utime;
  s.state = msg.state;
  s.arming_progress = msg.arming_progress;
  s.motion_time_us = msg.motion_time_us;
  s.reason = msg.reason;
  s.fault_latched = msg.fault_latched != 0;
  s.last_operator_id = msg.last_operator_id;
  s.last_operator_seq = msg.last_operator_seq;
  s.last_operator_reply = msg.last_operator_reply;
  return s;
}

OperatorSample ToSample(const operator_command_t& msg, bool authentic) {
  OperatorSample s;
  s.valid = true;
  s.operator_id = msg.operator_id;
  s.seq = msg.seq;
  s.command = msg.command;
  s.note = msg.note;
  s.authentic = authentic;
  return s;
}

}  // namespace stewart::viewer
