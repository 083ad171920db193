// stewart_viewer: the platform in 3D in a browser, live from the bus or from
// a recorded log (docs/operations.md, "The viewer").
//
//   stewart_viewer [--bind ADDR] [--port N] [--operator]   live
//   stewart_viewer --log runs/<run>/log.lcm                 play a recorded run
//
// The page is at http://<bind>:<port>/ (127.0.0.1:8080 by default).
#include <arpa/inet.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <thread>

#include "live_source.h"
#include "log_source.h"
#include "operator_console.h"
#include "stewart/config/viewer_config_loader.h"
#include "stewart/node/node_main.h"
#include "stewart/node/stop_signal.h"
#include "web_server.h"

namespace {

struct ViewerFlags {
  std::string bind_address;  ///< "" = viewer.bind_address
  int port = 0;              ///< 0 = viewer.port
  std::string log_path;      ///< "" = live
  bool operator_enabled = false;
  std::string web_root = STEWART_VIEWER_WEB_ROOT;
  std::string three_root = STEWART_VIEWER_THREE_ROOT;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace stewart;
  using namespace stewart::viewer;
  ViewerFlags flags;
  CLI::App* app_ptr = nullptr;
  ViewerConfig viewer_config;
  return NodeMain(
      argc, argv,
      {"stewart_viewer", "the platform in 3D in a browser, live or from a recorded log"},
      [&](CLI::App& app) {
        app_ptr = &app;
        app.add_option("--bind", flags.bind_address,
                       "address to listen on (default: viewer.bind_address, 127.0.0.1)");
        app.add_option("--port", flags.port, "TCP port of the page (default: viewer.port, 8080)")
            ->check(CLI::Range(1, 65535));
        app.add_option("--log", flags.log_path, "play this LCM log instead of the live bus");
        app.add_flag("--operator", flags.operator_enabled,
                     "show the operator buttons (arm, hold, resume, estop, reset): anyone "
                     "reaching the page can press them");
        app.add_option("--web-root", flags.web_root, "the page's folder (default: viewer/web)");
        app.add_option("--three-root", flags.three_root,
                       "three.js's folder (default: Debian's /usr/share/javascript/three)");
      },
      [&](StackConfig&) -> std::optional<ExitCode> {
        const std::vector<std::string> overlays = app_ptr->get_option("--overlay")->results();
        // NodeMain loaded the StackConfig from these; the viewer's section
        // comes from the same file and overlays.
        const auto config_path = app_ptr->get_option("--config")->as<std::string>();
        viewer_config = LoadViewerConfig(config_path, overlays);
        if (!flags.bind_address.empty()) {
          in_addr unused{};
          if (inet_pton(AF_INET, flags.bind_address.c_str(), &unused) != 1) {
            throw InputError("--bind", "'" + flags.bind_address + "' is not an IPv4 address");
          }
          viewer_config.bind_address = flags.bind_address;
        }
        if (flags.port != 0) viewer_config.port = flags.port;
        if (flags.operator_enabled && !flags.log_path.empty()) {
          throw InputError("--operator",
                           "a recorded log cannot be commanded (drop --log or --operator)");
        }
        return std::nullopt;
      },
      [&](const StackConfig& config, lcm::LCM* lcm) -> ExitCode {
        const FrameBuilder builder(config.platform, config.safety, config.home_pose, viewer_config);
        SessionInfo session;
        WebServerOptions web{viewer_config, flags.web_root, flags.three_root};
        std::unique_ptr<WebServer> server;
        std::unique_ptr<LogSource> log;
        std::unique_ptr<LiveSource> live;
        std::unique_ptr<OperatorConsole> console;
        if (!flags.log_path.empty()) {
          log = std::make_unique<LogSource>(flags.log_path, config, viewer_config, &builder);
          session.from_log = true;
          session.log_start_s = log->start_s();
          session.log_end_s = log->end_s();
          server = std::make_unique<WebServer>(
              web,
              [&] {
                log->NewViewer();
                return builder.Hello(session);
              },
              [&] { return log->NextFrame(); }, [&](const ClientMessage& m) { log->Handle(m); });
        } else {
          live = std::make_unique<LiveSource>(config, &builder);
          if (flags.operator_enabled) {
            console = std::make_unique<OperatorConsole>(config, lcm);
            session.operator_enabled = true;
            session.operator_id = console->operator_id();
          }
          server = std::make_unique<WebServer>(
              web, [&] { return builder.Hello(session); }, [&] { return live->NextFrame(); },
              [&](const ClientMessage& m) {
                if (m.kind != ClientMessage::Kind::kOperator) {
                  throw InputError("type", "play, pause, rate and seek need a log (--log)");
                }
                if (console == nullptr) {
                  throw InputError(
                      "command", "this viewer is read-only (start it with --operator to command)");
                }
                console->Send(m.operator_verb, "stewart_viewer");
              });
        }
        if (viewer_config.bind_address != "127.0.0.1") {
          spdlog::warn(
              "viewer: listening on {}, not loopback: anyone who reaches it sees the stack{}",
              viewer_config.bind_address, flags.operator_enabled ? " and can arm and stop it" : "");
        }
        spdlog::info("viewer: {} at {}{}", session.from_log ? flags.log_path : config.lcm.url,
                     server->url(),
                     flags.operator_enabled ? " (operator buttons on)" : " (read-only)");
        while (!StopRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        // The server first: its publisher thread reads the sources until it stops.
        server.reset();
        return ExitCode::kOk;
      });
}
