#include "stewart/stack/campaign_distribution.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "stewart/config/config_node.h"

namespace stewart {
namespace {

const std::vector<std::string> kTruthSections = {
    "platform", "legs", "actuators", "sensors", "initial_state", "latency", "disturbance"};

std::vector<std::string> SplitKey(const std::string& dotted_key) {
  std::vector<std::string> parts;
  std::stringstream in(dotted_key);
  std::string part;
  while (std::getline(in, part, '.')) parts.push_back(part);
  return parts;
}

YAML::Node FindDottedKey(const YAML::Node& root, const std::string& dotted_key) {
  YAML::Node node = YAML::Clone(root);
  for (const std::string& part : SplitKey(dotted_key)) {
    if (!node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    node = node[part];
    if (!node.IsDefined()) return node;
  }
  return node;
}

struct LawName {
  const char* name;
  SampleLaw law;
  SampleBase base;
};
constexpr LawName kLaws[] = {
    {"uniform", SampleLaw::kUniform, SampleBase::kAbsolute},
    {"normal", SampleLaw::kNormal, SampleBase::kAbsolute},
    {"scale_uniform", SampleLaw::kUniform, SampleBase::kScale},
    {"scale_normal", SampleLaw::kNormal, SampleBase::kScale},
    {"offset_uniform", SampleLaw::kUniform, SampleBase::kOffset},
    {"offset_normal", SampleLaw::kNormal, SampleBase::kOffset},
    {"fixed", SampleLaw::kFixed, SampleBase::kAbsolute},
};

// `value`, a list of `n` numbers at `key` of the entry `node`.
std::vector<double> Numbers(const ConfigNode& node, const std::string& key, const YAML::Node& value,
                            std::size_t n) {
  std::vector<double> out;
  if (!value.IsSequence() || value.size() != n) {
    node.Fail(key, "expected a list of " + std::to_string(n) + " numbers");
  }
  for (const YAML::Node& v : value) {
    try {
      out.push_back(v.as<double>());
    } catch (const YAML::Exception&) {
      node.Fail(key, "expected a list of " + std::to_string(n) + " numbers");
    }
    if (!std::isfinite(out.back())) node.Fail(key, "must be finite");
  }
  return out;
}

std::vector<double> BaseValues(const ConfigNode& node, const YAML::Node& config_root,
                               const ParameterSpec& spec) {
  const YAML::Node value = FindDottedKey(config_root, spec.key);
  if (!value.IsDefined() || value.IsNull()) {
    node.Fail("key", "'" + spec.key + "' has no value in the stack config to scale or offset");
  }
  std::vector<double> out;
  try {
    if (spec.size == 0) {
      if (!value.IsScalar()) node.Fail("size", "'" + spec.key + "' is a list in the config");
      out.push_back(value.as<double>());
    } else {
      if (!value.IsSequence() || static_cast<int>(value.size()) != spec.size) {
        node.Fail("size", "'" + spec.key + "' is not a list of " + std::to_string(spec.size) +
                              " in the stack config");
      }
      for (const YAML::Node& v : value) out.push_back(v.as<double>());
    }
  } catch (const YAML::Exception&) {
    node.Fail("key", "'" + spec.key + "' is not numeric in the stack config");
  }
  return out;
}

double Draw(const ParameterSpec& spec, std::size_t element, double base, std::mt19937_64* rng) {
  const auto [a, b] = spec.ab[spec.ab.size() == 1 ? 0 : element];
  double v = spec.law == SampleLaw::kUniform ? std::uniform_real_distribution<double>(a, b)(*rng)
                                             : std::normal_distribution<double>(a, b)(*rng);
  if (spec.clipped) v = std::clamp(v, spec.clip_lo, spec.clip_hi);
  switch (spec.base) {
    case SampleBase::kScale:
      return base * v;
    case SampleBase::kOffset:
      return base + v;
    case SampleBase::kAbsolute:
      break;
  }
  return v;
}

}  // namespace

void SetDottedKey(YAML::Node root, const std::string& dotted_key, const YAML::Node& value) {
  const std::vector<std::string> parts = SplitKey(dotted_key);
  // yaml-cpp nodes are handles: walking by assignment would rebind, so recurse.
  std::vector<YAML::Node> path{root};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node child = path.back()[parts[i]];
    if (!child.IsMap()) {
      path.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
      child = path.back()[parts[i]];
    }
    path.push_back(child);
  }
  path.back()[parts.back()] = value;
}

std::vector<std::string> CampaignDistribution::ColumnNames() const {
  std::vector<std::string> names;
  for (const ParameterSpec& p : parameters) {
    if (p.law == SampleLaw::kFixed) continue;
    if (p.size == 0 || p.same) {
      names.push_back(p.key);
    } else {
      for (int i = 0; i < p.size; ++i) names.push_back(p.key + "[" + std::to_string(i) + "]");
    }
  }
  return names;
}

CampaignDistribution ParseDistribution(const YAML::Node& distribution,
                                       const YAML::Node& config_root) {
  const ConfigNode root(distribution, "campaign");
  if (!distribution.IsMap()) throw ConfigError("campaign", "expected a mapping");
  CampaignDistribution d;
  d.name = root.Has("name") ? root.String("name") : "";
  std::vector<std::string> seen;
  const std::vector<ConfigNode> entries = root.List("parameters");
  for (std::size_t entry = 0; entry < entries.size(); ++entry) {
    const ConfigNode& p = entries[entry];
    const YAML::Node raw = distribution["parameters"][entry];
    ParameterSpec spec;
    spec.key = p.String("key");
    const std::string section = spec.key.substr(0, spec.key.find('.'));
    if (std::find(kTruthSections.begin(), kTruthSections.end(), section) == kTruthSections.end()) {
      p.Fail("key", "'" + spec.key +
                        "' is not a truth key (sections: platform, legs, "
                        "actuators, sensors, initial_state, latency, disturbance)");
    }
    if (std::find(seen.begin(), seen.end(), spec.key) != seen.end()) {
      p.Fail("key", "'" + spec.key + "' is given twice");
    }
    seen.push_back(spec.key);
    if (p.Has("size")) {
      spec.size = p.Int("size");
      if (spec.size < 1 || spec.size > 6) p.Fail("size", "must be 1 to 6");
    }
    if (p.Has("same")) {
      spec.same = p.Bool("same");
      if (spec.same && spec.size == 0) p.Fail("same", "needs a size");
    }
    int laws = 0;
    for (const LawName& law : kLaws) {
      if (!p.Has(law.name)) continue;
      ++laws;
      spec.law = law.law;
      spec.base = law.base;
    }
    if (laws != 1) {
      p.Fail("key", "'" + spec.key +
                        "' needs exactly one of uniform, normal, scale_uniform, "
                        "scale_normal, offset_uniform, offset_normal, fixed");
    }
    const std::string law_key = [&] {
      for (const LawName& law : kLaws)
        if (p.Has(law.name)) return std::string(law.name);
      return std::string();
    }();
    if (spec.law == SampleLaw::kFixed) {
      spec.fixed = YAML::Clone(raw[law_key]);
    } else {
      const YAML::Node law_value = raw[law_key];
      if (spec.size > 0 && law_value.IsSequence() && law_value.size() > 0 &&
          law_value[0].IsSequence()) {
        if (static_cast<int>(law_value.size()) != spec.size) {
          p.Fail(law_key, "needs one pair or " + std::to_string(spec.size) + " pairs");
        }
        for (std::size_t i = 0; i < law_value.size(); ++i) {
          const std::vector<double> pair =
              Numbers(p, law_key + "[" + std::to_string(i) + "]", law_value[i], 2);
          spec.ab.emplace_back(pair[0], pair[1]);
        }
      } else {
        const std::vector<double> pair = Numbers(p, law_key, law_value, 2);
        spec.ab.emplace_back(pair[0], pair[1]);
      }
      for (const auto& [a, b] : spec.ab) {
        if (spec.law == SampleLaw::kUniform && !(a <= b)) p.Fail(law_key, "needs a <= b");
        if (spec.law == SampleLaw::kNormal && !(b >= 0.0)) {
          p.Fail(law_key, "needs a standard deviation >= 0");
        }
      }
      if (p.Has("clip")) {
        const std::vector<double> clip = Numbers(p, "clip", raw["clip"], 2);
        spec.clipped = true;
        spec.clip_lo = clip[0];
        spec.clip_hi = clip[1];
        if (!(spec.clip_lo <= spec.clip_hi)) p.Fail("clip", "needs lo <= hi");
      }
      if (spec.base != SampleBase::kAbsolute) spec.base_values = BaseValues(p, config_root, spec);
    }
    d.parameters.push_back(spec);
  }
  return d;
}

SampledTruth SampleTruth(const CampaignDistribution& distribution, std::mt19937_64* rng) {
  SampledTruth out;
  out.truth = YAML::Node(YAML::NodeType::Map);
  for (const ParameterSpec& p : distribution.parameters) {
    if (p.law == SampleLaw::kFixed) {
      SetDottedKey(out.truth, p.key, YAML::Clone(p.fixed));
      continue;
    }
    if (p.size == 0) {
      const double v = Draw(p, 0, p.base_values.empty() ? 0.0 : p.base_values[0], rng);
      out.values.push_back(v);
      SetDottedKey(out.truth, p.key, YAML::Node(v));
      continue;
    }
    YAML::Node list(YAML::NodeType::Sequence);
    if (p.same) {
      // One draw of the law itself, then each element's base applied to it.
      ParameterSpec law = p;
      law.base = SampleBase::kAbsolute;
      const double drawn = Draw(law, 0, 0.0, rng);
      out.values.push_back(drawn);
      for (int i = 0; i < p.size; ++i) {
        const double base = p.base_values.empty() ? 0.0 : p.base_values[static_cast<size_t>(i)];
        list.push_back(p.base == SampleBase::kScale    ? base * drawn
                       : p.base == SampleBase::kOffset ? base + drawn
                                                       : drawn);
      }
    }
    for (int i = 0; !p.same && i < p.size; ++i) {
      const double base = p.base_values.empty() ? 0.0 : p.base_values[static_cast<size_t>(i)];
      const double v = Draw(p, static_cast<std::size_t>(i), base, rng);
      out.values.push_back(v);
      list.push_back(v);
    }
    list.SetStyle(YAML::EmitterStyle::Flow);
    SetDottedKey(out.truth, p.key, list);
  }
  return out;
}

}  // namespace stewart
