#include <arpa/inet.h>

#include "stewart/config/config_loader.h"
#include "stewart/config/viewer_config_loader.h"

namespace stewart {

viewer::ViewerConfig ParseViewerConfig(const ConfigNode& node) {
  viewer::ViewerConfig c;
  c.bind_address = node.String("bind_address");
  // civetweb takes a numeric address; a host name would fail later, less clearly.
  in_addr parsed{};
  if (inet_pton(AF_INET, c.bind_address.c_str(), &parsed) != 1) {
    node.Fail("bind_address", "'" + c.bind_address + "' is not an IPv4 address (e.g. 127.0.0.1)");
  }
  c.port = node.IntInRange("port", 1, 65535, "must be a TCP port, 1..65535");
  c.max_frame_rate_hz = node.PositiveDouble("max_frame_rate_hz");
  // Above the browsers' own refresh nothing more is shown, only sent.
  if (c.max_frame_rate_hz > 240.0) node.Fail("max_frame_rate_hz", "must not exceed 240 Hz");
  c.history_s = node.PositiveDouble("history_s");
  if (c.history_s > 600.0) node.Fail("history_s", "must not exceed 600 s");
  c.max_clients = node.IntInRange("max_clients", 1, 64, "must be within 1..64");
  return c;
}

viewer::ViewerConfig LoadViewerConfig(const std::string& path,
                                      const std::vector<std::string>& overlay_paths) {
  const ConfigNode root(LoadMergedConfigYaml(path, overlay_paths), "");
  if (!root.Has("viewer")) return {};
  return ParseViewerConfig(root.Child("viewer"));
}

}  // namespace stewart
