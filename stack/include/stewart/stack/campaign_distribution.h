#pragma once
// A campaign's distribution file (config/campaigns/*.yaml, docs/campaign.md):
// which truth keys to sample and how. Each run draws one truth from it.
//
//   name: bounds
//   parameters:
//     - {key: platform.mass_kg, scale_uniform: [0.8, 1.5]}          # x config value
//     - {key: platform.payload.mass_kg, uniform: [0.0, 0.3]}
//     - {key: platform.base_joint_angles_deg, size: 6, offset_uniform: [-0.5, 0.5]}
//     - {key: sensors.leg_offset_m, size: 6, normal: [0.0, 2.0e-4]}   # mean, std
//     - {key: disturbance.random_pushes, fixed: {rate_hz: 0.1, max_force_n: 5, duration_s: 0.2}}
//
// uniform / normal give the value; scale_* multiply the config's value of the
// key (element i for size > 1), offset_* add to it; `clip: [lo, hi]` bounds a
// drawn value; `fixed` copies a YAML value into every truth. For a list
// (size n), `same: true` draws once for every element (a common scale), and
// the law's value may be n pairs, one per element:
//     - {key: platform.payload.position_m, size: 3,
//        uniform: [[-0.1, 0.1], [-0.1, 0.1], [0.0, 0.05]]} Keys are truth
// keys (docs/simulation.md, "Truth").
#include <yaml-cpp/yaml.h>

#include <random>
#include <string>
#include <utility>
#include <vector>

namespace stewart {

enum class SampleLaw { kUniform, kNormal, kFixed };
enum class SampleBase { kAbsolute, kScale, kOffset };

struct ParameterSpec {
  std::string key;    ///< "platform.payload.mass_kg"
  int size = 0;       ///< 0: a scalar; n: a list of n values drawn independently...
  bool same = false;  ///< ... or (same: true) one draw applied to every element
  SampleLaw law = SampleLaw::kUniform;
  SampleBase base = SampleBase::kAbsolute;
  /// uniform: [a, b]; normal: mean a, std b. One pair for every element, or
  /// (written as a list of `size` pairs) one per element.
  std::vector<std::pair<double, double>> ab;
  bool clipped = false;
  double clip_lo = 0.0, clip_hi = 0.0;
  YAML::Node fixed;                 ///< kFixed: the value
  std::vector<double> base_values;  ///< the config's values (scale/offset), one per element
};

struct CampaignDistribution {
  std::string name;
  std::vector<ParameterSpec> parameters;
  /// The sampled columns, in order: "key" for a scalar, "key[i]" per element.
  std::vector<std::string> ColumnNames() const;
};

/// Parses a distribution; `config_root` (the stack config's YAML) gives the
/// values scale_* and offset_* apply to. Throws ConfigError naming the key
/// ("campaign.parameters[2].scale_uniform").
CampaignDistribution ParseDistribution(const YAML::Node& distribution,
                                       const YAML::Node& config_root);

/// One draw: the truth document and the drawn values in ColumnNames order.
/// Draws in the distribution's order, so a seed gives one truth.
struct SampledTruth {
  YAML::Node truth;
  std::vector<double> values;
};
SampledTruth SampleTruth(const CampaignDistribution& distribution, std::mt19937_64* rng);

/// Sets `value` at a dotted key ("platform.payload.mass_kg") of a mapping.
void SetDottedKey(YAML::Node root, const std::string& dotted_key, const YAML::Node& value);

}  // namespace stewart
