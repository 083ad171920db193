#pragma once
// The `viewer:` section (stewart_viewer, docs/operations.md "The viewer").
// Apart from the StackConfig: only the viewer reads it, and a run folder's
// config.yaml from before the section keeps loading with the defaults.
#include <string>
#include <vector>

#include "stewart/config/config_node.h"
#include "stewart/viewer/viewer_config.h"

namespace stewart {

/// Throws ConfigError naming the key ("viewer.port").
viewer::ViewerConfig ParseViewerConfig(const ConfigNode& viewer);
/// The section of the config at `path` with the overlays applied; the
/// defaults when the config has no `viewer:` section.
viewer::ViewerConfig LoadViewerConfig(const std::string& path,
                                      const std::vector<std::string>& overlay_paths);

}  // namespace stewart
