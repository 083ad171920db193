#pragma once
// The viewer's parameters (config `viewer:` section, docs/operations.md,
// "The viewer"). The struct only: config/viewer_config_loader.h parses it.
#include <string>

namespace stewart::viewer {

struct ViewerConfig {
  /// Address the HTTP server listens on. Loopback by default: the page shows
  /// the whole stack and, with --operator, can arm and stop it.
  std::string bind_address = "127.0.0.1";
  int port = 8080;
  /// Upper bound of the frames pushed to each browser (Hz).
  double max_frame_rate_hz = 60.0;
  /// Length of the page's strip charts (s of stack time).
  double history_s = 10.0;
  /// Browsers served at once; one more is refused (each has its own sender).
  int max_clients = 8;
};

}  // namespace stewart::viewer
