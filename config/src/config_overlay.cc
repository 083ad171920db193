// Config overlays (docs/operations.md, "Config overlays"): a small YAML file
// of the keys to change, e.g. the platform's identified mass properties.
#include "stewart/config/config_loader.h"

namespace stewart {
namespace {

std::string Join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

// Merges `overlay` (a mapping) into `config` (the mapping at `path`).
void MergeMapping(const YAML::Node& overlay, const std::string& path, const std::string& name,
                  YAML::Node config) {
  for (const auto& item : overlay) {
    const std::string key = item.first.as<std::string>();
    const std::string key_path = Join(path, key);
    const YAML::Node existing = static_cast<const YAML::Node&>(config)[key];  // no insertion
    if (!existing.IsDefined()) {
      throw ConfigError(key_path, "not a key of the config (overlay '" + name + "')");
    }
    const YAML::Node& value = item.second;
    if (existing.IsMap() != value.IsMap()) {
      throw ConfigError(key_path, std::string(existing.IsMap() ? "the config has a section here"
                                                               : "the config has a value here") +
                                      ", the overlay '" + name + "' " +
                                      (value.IsMap() ? "a mapping" : "a value"));
    }
    if (value.IsMap()) {
      MergeMapping(value, key_path, name, config[key]);
    } else {
      // A value or a whole sequence replaces the config's (a list of limits
      // is one setting, not items to merge one by one).
      config[key] = YAML::Clone(value);
    }
  }
}

}  // namespace

void ApplyConfigOverlay(const YAML::Node& overlay, const std::string& overlay_name,
                        YAML::Node* config) {
  if (!overlay.IsDefined() || overlay.IsNull()) return;  // an empty file changes nothing
  if (!overlay.IsMap()) throw ConfigError("<overlay>", "'" + overlay_name + "' is not a mapping");
  if (!config->IsMap()) throw ConfigError("<root>", "expected a mapping");
  MergeMapping(overlay, "", overlay_name, *config);
}

}  // namespace stewart
