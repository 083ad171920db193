#pragma once
// The one loader of the one YAML config (docs/operations.md, "Configuration").
#include <string>
#include <vector>

#include "stewart/config/config_node.h"
#include "stewart/config/stack_config.h"

namespace stewart {

/// Loads and validates; throws ConfigError naming the key and the reason.
StackConfig LoadStackConfig(const std::string& path);

/// The config at `path` with each overlay file applied in order
/// (ApplyConfigOverlay), then validated. source_path is `path`: a plant's
/// truth overrides the file, not the overlays (truth_loader.h).
StackConfig LoadStackConfig(const std::string& path, const std::vector<std::string>& overlay_paths);

/// The merged document itself, unparsed (what tools/launch.sh writes as the
/// run folder's config.yaml).
YAML::Node LoadMergedConfigYaml(const std::string& path,
                                const std::vector<std::string>& overlay_paths);

/// Applies an overlay to a config document in place, key by key: a mapping
/// merges into the mapping of the same key (recursively), anything else
/// (a number, a string, a whole sequence) replaces the config's value. Only
/// keys the config already has may be given: another key, or a mapping where
/// the config has a value (or the reverse), throws ConfigError naming the key
/// ("platform.mass_kgg") and `overlay_name`.
void ApplyConfigOverlay(const YAML::Node& overlay, const std::string& overlay_name,
                        YAML::Node* config);

/// A YAML file, unparsed into structs; ConfigError("<file>" or "<yaml>")
/// naming the file when it cannot be read or is not YAML.
YAML::Node LoadYamlFile(const std::string& path);
StackConfig ParseStackConfig(const std::string& yaml_text);

/// Cross-section checks (home pose inside the stroke and inside every limit,
/// ...). Called by the loaders; exposed for configs built in code.
void ValidateStackConfig(const StackConfig& config);

/// Default config file: $STEWART_CONFIG, else config/platform.yaml of the
/// source tree this binary was built from.
std::string DefaultConfigPath();

}  // namespace stewart
