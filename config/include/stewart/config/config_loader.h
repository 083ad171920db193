#pragma once
// The one loader of the one YAML config (docs/operations.md, "Configuration").
#include <string>

#include "stewart/config/config_node.h"
#include "stewart/config/stack_config.h"

namespace stewart {

/// Loads and validates; throws ConfigError naming the key and the reason.
StackConfig LoadStackConfig(const std::string& path);

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
