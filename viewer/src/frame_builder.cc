#include "stewart/viewer/frame_builder.h"

#include <algorithm>
#include <utility>

#include "stewart/model/kinematics.h"
#include "stewart/safety/supervisor.h"

namespace stewart::viewer {
namespace {

using nlohmann::json;

template <class Vec>
json Array(const Vec& v, int n) {
  json a = json::array();
  for (int i = 0; i < n; ++i) a.push_back(v[i]);
  return a;
}

json Points(const Eigen::Matrix<double, 3, kNumLegs>& m) {
  json a = json::array();
  for (int i = 0; i < kNumLegs; ++i) a.push_back({m(0, i), m(1, i), m(2, i)});
  return a;
}

json Limit(int axis, const std::optional<double>& lower, const std::optional<double>& upper) {
  return {{"axis", axis},
          {"lower", lower ? json(*lower) : json(nullptr)},
          {"upper", upper ? json(*upper) : json(nullptr)}};
}

json State(const StateSample& s) {
  if (!s.valid) return nullptr;
  return {
      {"utime_us", s.utime_us}, {"q", Array(s.q, 6)}, {"qd", Array(s.qd, 6)}, {"status", s.status}};
}

json Force(const ForceSample& f) {
  if (!f.valid) return nullptr;
  return {{"utime_us", f.utime_us}, {"force_n", Array(f.force_n, 6)}, {"flags", f.flags}};
}

json Barriers(const std::vector<BarrierSample>& barriers) {
  json a = json::array();
  for (const BarrierSample& b : barriers)
    a.push_back({{"name", b.name}, {"h", b.h}, {"w", b.weight}});
  return a;
}

}  // namespace

const char* SupervisorStateName(int state) {
  static constexpr const char* kNames[] = {"DISARMED", "ARMING", "ARMED", "HOLD", "ESTOP"};
  return state >= 0 && state < 5 ? kNames[state] : "UNKNOWN";
}

const char* HealthStateName(int state) {
  static constexpr const char* kNames[] = {"STARTING", "OK", "DEGRADED", "FAULT", "STOPPED"};
  return state >= 0 && state < 5 ? kNames[state] : "UNKNOWN";
}

const char* FilterCaseName(int active_case) {
  static constexpr const char* kNames[] = {"none", "position",   "velocity",
                                           "both", "infeasible", "fallback"};
  return active_case >= 0 && active_case < 6 ? kNames[active_case] : "unknown";
}

FrameBuilder::FrameBuilder(PlatformParams platform, SafetyConfig safety, Vector6d home_pose,
                           ViewerConfig config)
    : platform_(std::move(platform)),
      safety_(std::move(safety)),
      home_pose_(std::move(home_pose)),
      config_(std::move(config)) {}

json FrameBuilder::Hello(const SessionInfo& session) const {
  json position = json::array();
  for (const PositionLimitConfig& l : safety_.position_limits) {
    position.push_back(Limit(l.axis, l.lower, l.upper));
  }
  json velocity = json::array();
  for (const VelocityLimitConfig& l : safety_.velocity_limits) {
    velocity.push_back(Limit(l.axis, l.lower, l.upper));
  }
  return {{"type", "hello"},
          {"mode", session.from_log ? "log" : "live"},
          {"operator", session.operator_enabled},
          {"operator_id", std::to_string(session.operator_id)},
          {"log", {{"start_s", session.log_start_s}, {"end_s", session.log_end_s}}},
          {"platform",
           {{"base_joints_in_B_m", Points(platform_.base_joints_in_B_m)},
            {"platform_joints_in_P_m", Points(platform_.platform_joints_in_P_m)},
            {"leg_min_length_m", platform_.leg_min_length_m},
            {"leg_max_length_m", platform_.leg_max_length_m},
            {"home_pose", Array(home_pose_, 6)}}},
          {"limits", {{"position", position}, {"velocity", velocity}}},
          {"history_s", config_.history_s},
          {"max_frame_rate_hz", config_.max_frame_rate_hz}};
}

json FrameBuilder::Frame(const ViewerSnapshot& s) const {
  json frame = {{"type", "frame"},
                {"estimate", State(s.estimate)},
                {"truth", State(s.truth)},
                {"nominal", Force(s.nominal)},
                {"safe", Force(s.safe)}};
  frame["setpoint"] = s.setpoint.valid ? Array(s.setpoint.q_des, 6) : json(nullptr);
  if (s.estimate.valid) {
    // The legs at the estimate: the pose the stack acts on.
    const LegGeometry legs = ComputeLegGeometry(platform_, s.estimate.q);
    Eigen::Matrix<double, 3, kNumLegs> platform_joints_in_B_m = legs.platform_offset_in_B_m;
    platform_joints_in_B_m.colwise() += s.estimate.q.head<3>();
    const double stroke_m = platform_.leg_max_length_m - platform_.leg_min_length_m;
    json use = json::array();
    json near_end = json::array();
    for (int i = 0; i < kNumLegs; ++i) {
      const double share = (legs.length_m(i) - platform_.leg_min_length_m) / stroke_m;
      use.push_back(share);
      near_end.push_back(share < kStrokeWarningShare || share > 1.0 - kStrokeWarningShare);
    }
    frame["legs"] = {{"length_m", Array(legs.length_m, 6)},
                     {"stroke_use", use},
                     {"near_end", near_end},
                     {"platform_joints_in_B_m", Points(platform_joints_in_B_m)}};
  } else {
    frame["legs"] = nullptr;
  }
  if (s.diagnostics.valid) {
    const DiagnosticsSample& d = s.diagnostics;
    frame["diagnostics"] = {{"utime_us", d.utime_us},
                            {"case", d.active_case},
                            {"case_name", FilterCaseName(d.active_case)},
                            {"position", Barriers(d.position)},
                            {"velocity", Barriers(d.velocity)},
                            {"h_pos", d.h_pos},
                            {"h_vel", d.h_vel},
                            {"correction_norm_n", d.correction_norm_n},
                            {"flags", d.flags},
                            {"compute_us", d.compute_us}};
  } else {
    frame["diagnostics"] = nullptr;
  }
  if (s.supervisor.valid) {
    const SupervisorSample& v = s.supervisor;
    frame["supervisor"] = {{"state", v.state},
                           {"state_name", SupervisorStateName(v.state)},
                           {"arming_progress", v.arming_progress},
                           {"motion_time_s", static_cast<double>(v.motion_time_us) * 1e-6},
                           {"reason", v.reason},
                           {"fault_latched", v.fault_latched},
                           {"last_operator_id", std::to_string(v.last_operator_id)},
                           {"last_operator_seq", v.last_operator_seq},
                           {"last_operator_reply", v.last_operator_reply}};
  } else {
    frame["supervisor"] = nullptr;
  }
  if (s.last_operator_command.valid) {
    const OperatorSample& o = s.last_operator_command;
    const bool known = o.command >= static_cast<int>(safety::OperatorCommand::kArm) &&
                       o.command <= static_cast<int>(safety::OperatorCommand::kHeartbeat);
    frame["operator_command"] = {
        {"operator_id", std::to_string(o.operator_id)},
        {"seq", o.seq},
        {"command",
         known ? safety::ToString(static_cast<safety::OperatorCommand>(o.command)) : "unknown"},
        {"note", o.note},
        {"authentic", o.authentic}};
  } else {
    frame["operator_command"] = nullptr;
  }
  json health = json::array();
  for (const auto& [name, h] : s.health) {
    health.push_back(
        {{"name", name},
         {"state_name", HealthStateName(h.state)},
         {"worst_state_name", HealthStateName(h.worst_state)},
         {"fault_latched", h.fault_latched},
         {"last_error", h.last_error},
         {"messages_in", h.messages_in},
         {"rejected_inputs", h.rejected_inputs},
         {"latency_p99_us", h.latency_p99_us >= 0 ? json(h.latency_p99_us) : json(nullptr)},
         {"missed_ticks", h.missed_ticks >= 0 ? json(h.missed_ticks) : json(nullptr)}});
  }
  frame["health"] = health;
  frame["t_s"] = s.estimate.valid ? static_cast<double>(s.estimate.utime_us) * 1e-6 : 0.0;
  return frame;
}

}  // namespace stewart::viewer
