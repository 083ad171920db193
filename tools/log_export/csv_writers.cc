#include "csv_writers.h"

#include <cstring>
#include <iomanip>
#include <memory>

#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/operator_command_t.hpp"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {
namespace {

constexpr const char* kAxes[6] = {"x", "y", "z", "phi", "theta", "psi"};

std::string AxisColumns(const std::string& name, const std::string& unit_lin,
                        const std::string& unit_ang) {
  std::string s;
  for (int i = 0; i < 6; ++i) {
    s += "," + name + "_" + kAxes[i] + "_" + (i < 3 ? unit_lin : unit_ang);
  }
  return s;
}

std::string IndexedColumns(const std::string& name, int n, const std::string& unit) {
  std::string s;
  for (int i = 0; i < n; ++i) s += "," + name + std::to_string(i) + "_" + unit;
  return s;
}

template <int N>
void Values(std::ostream& out, const double (&values)[N]) {
  for (int i = 0; i < N; ++i) out << ',' << values[i];
}

void Values(std::ostream& out, const std::vector<double>& values, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) out << ',' << (i < values.size() ? values[i] : 0.0);
}

template <typename Msg>
class TypedWriter : public CsvChannelWriter {
 public:
  bool WriteRow(const void* data, int size, std::ostream& out) const override {
    Msg msg;
    if (msg.decode(data, 0, size) != size) return false;
    out << msg.utime << ',' << msg.seq << ',' << msg.sample_utime;
    Row(msg, out);
    out << '\n';
    return true;
  }
  std::string Header() const override { return "utime_us,seq,sample_utime_us" + Columns(); }
  std::optional<MessageStamp> Stamp(const void* data, int size) const override {
    Msg msg;
    if (msg.decode(data, 0, size) != size) return std::nullopt;
    return MessageStamp{msg.seq, msg.utime, Publisher(msg)};
  }

 protected:
  virtual std::string Publisher(const Msg& /*msg*/) const { return ""; }
  virtual std::string Columns() const = 0;
  virtual void Row(const Msg& msg, std::ostream& out) const = 0;
};

class SensorWriter : public TypedWriter<sensor_t> {
  std::string Columns() const override {
    return IndexedColumns("leg_length", 6, "m") + ",gyro_x_radps,gyro_y_radps,gyro_z_radps" +
           ",accel_x_mps2,accel_y_mps2,accel_z_mps2,has_orientation" +
           ",roll_rad,pitch_rad,yaw_rad,status";
  }
  void Row(const sensor_t& m, std::ostream& out) const override {
    Values(out, m.leg_length_m);
    Values(out, m.gyro_radps);
    Values(out, m.accel_mps2);
    out << ',' << int{m.has_orientation};
    Values(out, m.orientation_rpy_rad);
    out << ',' << m.status;
  }
};

class StateWriter : public TypedWriter<state_t> {
  std::string Columns() const override {
    return AxisColumns("q", "m", "rad") + AxisColumns("qd", "mps", "radps") +
           AxisColumns("q_std", "m", "rad") + AxisColumns("qd_std", "mps", "radps") + ",status";
  }
  void Row(const state_t& m, std::ostream& out) const override {
    Values(out, m.q);
    Values(out, m.qd);
    Values(out, m.q_std);
    Values(out, m.qd_std);
    out << ',' << m.status;
  }
};

class SetpointWriter : public TypedWriter<setpoint_t> {
  std::string Columns() const override {
    return AxisColumns("q_des", "m", "rad") + AxisColumns("qd_des", "mps", "radps") +
           AxisColumns("qdd_des", "mps2", "radps2");
  }
  void Row(const setpoint_t& m, std::ostream& out) const override {
    Values(out, m.q_des);
    Values(out, m.qd_des);
    Values(out, m.qdd_des);
  }
};

class ForceCommandWriter : public TypedWriter<force_command_t> {
  std::string Columns() const override { return IndexedColumns("force", 6, "n") + ",flags"; }
  void Row(const force_command_t& m, std::ostream& out) const override {
    Values(out, m.force_n);
    out << ',' << m.flags;
  }
};

class DiagnosticsWriter : public TypedWriter<safety_diagnostics_t> {
 public:
  // Which barrier each indexed column is: group, index, name.
  std::string SidecarName() const override { return "barriers"; }
  std::string Sidecar(const void* data, int size) const override {
    safety_diagnostics_t m;
    if (m.decode(data, 0, size) != size) return "";
    std::string s = "group,index,name\n";
    for (int i = 0; i < m.num_position; ++i) {
      s += "position," + std::to_string(i) + "," + m.position_names[static_cast<size_t>(i)] + "\n";
    }
    for (int i = 0; i < m.num_velocity; ++i) {
      s += "velocity," + std::to_string(i) + "," + m.velocity_names[static_cast<size_t>(i)] + "\n";
    }
    return s;
  }

 private:
  // Barrier arrays vary in length between configs; the CSV keeps the
  // composed quantities, which every config has, plus every barrier up to
  // the most a config can have (safety/constraint_set.h: 2 per axis and 2
  // per leg for position, 2 per axis for velocity); names in the sidecar.
  static constexpr int kPositionColumns = 24;
  static constexpr int kVelocityColumns = 12;
  std::string Columns() const override {
    return ",variant,correction_metric,active_case,infeasible,fallback_reason,h_pos,h_vel,psi_p,"
           "psi_v,mu_p,mu_v" +
           IndexedColumns("g_p", 6, "") + IndexedColumns("g_v", 6, "") +
           IndexedColumns("f_des", 6, "n") + IndexedColumns("f_safe", 6, "n") +
           IndexedColumns("mu_force", 6, "") + ",correction_norm_n,compute_ns,num_position," +
           "num_velocity" + IndexedColumns("h_position", kPositionColumns, "") +
           IndexedColumns("h_velocity", kVelocityColumns, "") +
           IndexedColumns("w_position", kPositionColumns, "") +
           IndexedColumns("w_velocity", kVelocityColumns, "") +
           IndexedColumns("mu_position", kPositionColumns, "") +
           IndexedColumns("mu_velocity", kVelocityColumns, "") +
           IndexedColumns("f_nominal", 6, "n") + ",nominal_scale,flags";
  }
  void Row(const safety_diagnostics_t& m, std::ostream& out) const override {
    out << ',' << int{m.variant} << ',' << int{m.correction_metric} << ',' << int{m.active_case}
        << ',' << int{m.infeasible} << ',' << m.fallback_reason << ',' << m.h_pos << ',' << m.h_vel
        << ',' << m.psi_p << ',' << m.psi_v << ',' << m.mu_p << ',' << m.mu_v;
    Values(out, m.g_p);
    Values(out, m.g_v);
    Values(out, m.f_des);
    Values(out, m.f_safe);
    Values(out, m.mu_force);
    out << ',' << m.correction_norm << ',' << m.compute_ns << ',' << m.num_position << ','
        << m.num_velocity;
    Values(out, m.h_position, kPositionColumns);
    Values(out, m.h_velocity, kVelocityColumns);
    Values(out, m.w_position, kPositionColumns);
    Values(out, m.w_velocity, kVelocityColumns);
    Values(out, m.mu_position, kPositionColumns);
    Values(out, m.mu_velocity, kVelocityColumns);
    Values(out, m.f_nominal);
    out << ',' << m.nominal_scale << ',' << m.flags;
  }
};

/// Free text inside a quoted CSV field: no quote, no line break.
std::string Quotable(std::string text) {
  for (char& c : text) {
    if (c == '"' || c == '\n') c = '\'';
  }
  return text;
}

class HealthWriter : public TypedWriter<health_t> {
  // Every process heartbeats on one channel, each with its own seq.
  std::string Publisher(const health_t& m) const override { return m.name; }
  std::string Columns() const override {
    return ",name,state,worst_state,fault_latched,messages_in,messages_out,rejected_inputs,"
           "period_us,messages_in_delta,messages_out_delta,rejected_inputs_delta,counters,"
           "counter_deltas,last_error,latched_error";
  }
  void Row(const health_t& m, std::ostream& out) const override {
    out << ',' << m.name << ',' << int{m.state} << ',' << int{m.worst_state} << ','
        << int{m.fault_latched} << ',' << m.messages_in << ',' << m.messages_out << ','
        << m.rejected_inputs << ',' << m.period_us << ',' << m.messages_in_delta << ','
        << m.messages_out_delta << ',' << m.rejected_inputs_delta << ",\"";
    for (std::size_t i = 0; i < m.counter_names.size(); ++i) {
      out << (i ? ";" : "") << m.counter_names[i] << '=' << m.counter_values[i];
    }
    out << "\",\"";
    for (std::size_t i = 0; i < m.counter_names.size(); ++i) {
      out << (i ? ";" : "") << m.counter_names[i] << '=' << m.counter_deltas[i];
    }
    out << "\",\"" << Quotable(m.last_error) << "\",\"" << Quotable(m.latched_error) << '"';
  }
};

class SupervisorWriter : public TypedWriter<supervisor_state_t> {
  std::string Columns() const override {
    return ",session_id,state,arming_progress,motion_time_us,transitions,"
           "operator_commands_accepted,operator_commands_rejected,fault_latched,reason,"
           "last_operator_reply";
  }
  void Row(const supervisor_state_t& m, std::ostream& out) const override {
    out << ',' << m.session_id << ',' << int{m.state} << ',' << m.arming_progress << ','
        << m.motion_time_us << ',' << m.transitions << ',' << m.operator_commands_accepted << ','
        << m.operator_commands_rejected << ',' << int{m.fault_latched} << ",\""
        << Quotable(m.reason) << "\",\"" << Quotable(m.last_operator_reply) << '"';
  }
};

class OperatorWriter : public TypedWriter<operator_command_t> {
  // Consoles share the channel and number their commands each, from any
  // start: no stream to check.
  std::optional<MessageStamp> Stamp(const void* /*data*/, int /*size*/) const override {
    return std::nullopt;
  }
  std::string Columns() const override { return ",operator_id,command,note"; }
  void Row(const operator_command_t& m, std::ostream& out) const override {
    out << ',' << m.operator_id << ',' << int{m.command} << ",\"" << Quotable(m.note) << '"';
  }
};

int64_t PayloadHash(const void* data, int size) {
  if (size < 8) return 0;
  const auto* bytes = static_cast<const uint8_t*>(data);
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | bytes[i];
  return static_cast<int64_t>(hash);
}

}  // namespace

const CsvChannelWriter* FindCsvWriter(const void* data, int size) {
  static const SensorWriter sensor;
  static const StateWriter state;
  static const SetpointWriter setpoint;
  static const ForceCommandWriter command;
  static const DiagnosticsWriter diagnostics;
  static const HealthWriter health;
  static const SupervisorWriter supervisor;
  static const OperatorWriter operator_command;
  const int64_t hash = PayloadHash(data, size);
  if (hash == sensor_t::getHash()) return &sensor;
  if (hash == state_t::getHash()) return &state;
  if (hash == setpoint_t::getHash()) return &setpoint;
  if (hash == force_command_t::getHash()) return &command;
  if (hash == safety_diagnostics_t::getHash()) return &diagnostics;
  if (hash == health_t::getHash()) return &health;
  if (hash == supervisor_state_t::getHash()) return &supervisor;
  if (hash == operator_command_t::getHash()) return &operator_command;
  return nullptr;
}

}  // namespace stewart
