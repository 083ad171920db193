#include "stewart/controller/scenario.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Quintic s(tau) with s(0)=0, s(1)=1 and zero first and second derivatives at
// both ends (minimum-jerk point-to-point move).
struct Quintic {
  double s, ds, dds;  // d/dtau
};
Quintic MinimumJerk(double tau) {
  const double t2 = tau * tau, t3 = t2 * tau, t4 = t3 * tau, t5 = t4 * tau;
  return {10.0 * t3 - 15.0 * t4 + 6.0 * t5, 30.0 * t2 - 60.0 * t3 + 30.0 * t4,
          60.0 * tau - 180.0 * t2 + 120.0 * t3};
}

Setpoint EvaluateSegment(const ScenarioSegment& seg, double t_s) {
  Setpoint sp;
  switch (seg.type) {
    case SegmentType::kStep:
      sp.q_des = seg.q_des;
      break;
    case SegmentType::kSine: {
      const double w = 2.0 * kPi / seg.period_s;
      const double tau = t_s - seg.start_s;
      for (int j = 0; j < kNumAxes; ++j) {
        const double angle = w * tau + seg.phase_rad(j);
        sp.q_des(j) = seg.center(j) + seg.amplitude(j) * std::sin(angle);
        sp.qd_des(j) = seg.amplitude(j) * w * std::cos(angle);
        sp.qdd_des(j) = -seg.amplitude(j) * w * w * std::sin(angle);
      }
      break;
    }
    case SegmentType::kMove: {
      const double T = seg.end_s - seg.start_s;
      const double tau = std::clamp((t_s - seg.start_s) / T, 0.0, 1.0);
      const Quintic s = MinimumJerk(tau);
      const Vector6d delta = seg.q_des - seg.q_from;
      sp.q_des = seg.q_from + s.s * delta;
      if (tau < 1.0) {
        sp.qd_des = (s.ds / T) * delta;
        sp.qdd_des = (s.dds / (T * T)) * delta;
      }
      break;
    }
  }
  return sp;
}

void RejectUnknownKeys(const YAML::Node& node, const std::string& path,
                       const std::set<std::string>& allowed) {
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (allowed.count(key) == 0) {
      std::string list;
      for (const auto& a : allowed) list += " " + a;
      throw ConfigError(path.empty() ? key : path + "." + key,
                        "unknown key (allowed:" + list + ")");
    }
  }
}

ScenarioSegment ParseSegment(const ConfigNode& node, const YAML::Node& yaml) {
  ScenarioSegment seg;
  seg.start_s = node.NonNegativeDouble("start_s");
  const std::string type = node.Choice("type", {"step", "sine", "move"});
  if (type == "step") {
    RejectUnknownKeys(yaml, node.path(), {"start_s", "type", "q_des"});
    seg.type = SegmentType::kStep;
    seg.q_des = node.Vec6("q_des");
  } else if (type == "move") {
    RejectUnknownKeys(yaml, node.path(), {"start_s", "type", "q_des", "q_from"});
    seg.type = SegmentType::kMove;
    seg.q_des = node.Vec6("q_des");
    if (node.Has("q_from")) seg.q_from = node.Vec6("q_from");
  } else {
    RejectUnknownKeys(yaml, node.path(),
                      {"start_s", "type", "center", "amplitude", "period_s", "phase_deg"});
    seg.type = SegmentType::kSine;
    seg.center = node.Vec6("center");
    seg.amplitude = node.Vec6("amplitude");
    seg.period_s = node.PositiveDouble("period_s");
    if (node.Has("phase_deg")) seg.phase_rad = node.Vec6("phase_deg") * (kPi / 180.0);
  }
  return seg;
}

Scenario ParseRoot(const YAML::Node& yaml, const std::string& source) {
  if (!yaml.IsMap()) throw ConfigError(source.empty() ? "<root>" : source, "expected a mapping");
  RejectUnknownKeys(yaml, "", {"name", "description", "duration_s", "segments"});
  const ConfigNode root(yaml, "");
  const std::string name = root.String("name");
  const double duration_s = root.PositiveDouble("duration_s");
  const std::vector<ConfigNode> nodes = root.List("segments");
  if (nodes.empty()) root.Fail("segments", "needs at least one segment");
  std::vector<ScenarioSegment> segments;
  std::vector<bool> has_from;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    ScenarioSegment seg = ParseSegment(nodes[i], yaml["segments"][i]);
    has_from.push_back(nodes[i].Has("q_from"));
    if (i == 0 && seg.start_s != 0.0) nodes[i].Fail("start_s", "the first segment must start at 0");
    if (i > 0 && !(seg.start_s > segments.back().start_s)) {
      nodes[i].Fail("start_s", "must be greater than the previous segment's start_s");
    }
    if (seg.start_s > duration_s) nodes[i].Fail("start_s", "is after duration_s");
    if (seg.type == SegmentType::kMove && i == 0 && !has_from[i]) {
      nodes[i].Fail("q_from", "missing required key (the first segment has no pose to start from)");
    }
    if (i > 0) segments.back().end_s = seg.start_s;
    segments.push_back(seg);
  }
  segments.back().end_s = duration_s;
  if (segments.back().type == SegmentType::kMove && !(duration_s > segments.back().start_s)) {
    nodes.back().Fail("start_s", "a move must end before duration_s");
  }
  for (std::size_t i = 1; i < segments.size(); ++i) {
    if (segments[i].type == SegmentType::kMove && !has_from[i]) {
      segments[i].q_from = EvaluateSegment(segments[i - 1], segments[i - 1].end_s).q_des;
    }
  }
  return Scenario(name, duration_s, std::move(segments));
}

}  // namespace

Scenario::Scenario(std::string name, double duration_s, std::vector<ScenarioSegment> segments)
    : name_(std::move(name)), duration_s_(duration_s), segments_(std::move(segments)) {}

Setpoint Scenario::Evaluate(double t_s) const {
  const double t = std::max(t_s, 0.0);
  // Segment with the last start_s <= t (segments_[0].start_s == 0).
  const auto next = std::upper_bound(
      segments_.begin(), segments_.end(), t,
      [](double value, const ScenarioSegment& seg) { return value < seg.start_s; });
  return EvaluateSegment(*(next - 1), t);
}

Scenario ParseScenario(const std::string& yaml_text, const std::string& source) {
  YAML::Node yaml;
  try {
    yaml = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source.empty() ? "<yaml>" : source,
                      std::string("not valid YAML: ") + e.what());
  }
  try {
    return ParseRoot(yaml, source);
  } catch (const ConfigError& e) {
    if (source.empty()) throw;
    throw ConfigError(source + ": " + e.key(), e.reason());
  }
}

Scenario LoadScenario(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError(path, "cannot open scenario file");
  std::stringstream text;
  text << file.rdbuf();
  return ParseScenario(text.str(), path);
}

std::string ResolveScenarioPath(const std::string& name_or_path) {
  const bool is_path =
      name_or_path.find('/') != std::string::npos ||
      (name_or_path.size() > 5 && name_or_path.compare(name_or_path.size() - 5, 5, ".yaml") == 0);
  if (is_path) return name_or_path;
  return std::string(STEWART_SOURCE_DIR) + "/config/scenarios/" + name_or_path + ".yaml";
}

std::optional<double> FirstTimeOutsideWorkspace(const Scenario& scenario,
                                                const PlatformParams& platform, double step_s) {
  const long steps = static_cast<long>(std::ceil(scenario.duration_s() / step_s));
  for (long k = 0; k <= steps; ++k) {
    const double t = std::min(static_cast<double>(k) * step_s, scenario.duration_s());
    if (!PoseInWorkspace(platform, scenario.Evaluate(t).q_des)) return t;
  }
  return std::nullopt;
}

}  // namespace stewart
