#include "stewart/config/scenario_loader.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace stewart {
namespace {

constexpr double kPi = 3.14159265358979323846;

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

}  // namespace stewart
