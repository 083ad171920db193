#pragma once
// Scenario files (config/scenarios/*.yaml, format in docs/controller.md) into
// the controller's Scenario.
#include <string>

#include "stewart/config/config_node.h"
#include "stewart/controller/scenario.h"

namespace stewart {

/// Parses scenario YAML. Throws ConfigError naming the key ("segments[2].q_des")
/// and the reason; `source` is put in front of the key to name the file.
Scenario ParseScenario(const std::string& yaml_text, const std::string& source = "");
Scenario LoadScenario(const std::string& path);

/// "paper" -> <source tree>/config/scenarios/paper.yaml; anything with a '/'
/// or ending in .yaml is taken as a path.
std::string ResolveScenarioPath(const std::string& name_or_path);

}  // namespace stewart
