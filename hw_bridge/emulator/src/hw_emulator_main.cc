// hw_emulator: speaks the device side of docs/wire-protocol.md over UDP or a
// pseudo-terminal, backed by the platform model, with the device watchdog.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <thread>

#include "stewart/config/stack_config.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "stewart/hw_emulator/model_backend.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  using namespace stewart;
  using Clock = std::chrono::steady_clock;
  CLI::App app{"hw_emulator: the device side of the wire protocol on the platform model"};
  std::string config_path = DefaultConfigPath();
  std::string transport = "udp", pty_link, log_level = "info";
  std::string bind_host, host;
  int device_port = -1, host_port = -1;
  double rate_hz = 0.0, duration_s = 0.0;
  int drop_every = 0;
  bool no_noise = false;
  app.add_option("-c,--config", config_path, "YAML config")->capture_default_str();
  app.add_option("--transport", transport, "udp | pty")
      ->check(CLI::IsMember({"udp", "pty"}))
      ->capture_default_str();
  app.add_option("--pty-link", pty_link, "pty: create this symlink to the slave device");
  app.add_option("--bind-host", bind_host, "udp: address to bind (default hw_bridge.device_host)");
  app.add_option("--device-port", device_port, "udp: port to bind (default hw_bridge.device_port)");
  app.add_option("--host", host, "udp: bridge address (default hw_bridge.local_host)");
  app.add_option("--host-port", host_port, "udp: bridge port (default hw_bridge.local_port)");
  app.add_option("--rate-hz", rate_hz, "sample rate (default sensors.rate_hz)");
  app.add_option("--duration-s", duration_s, "stop after this long (0: until SIGINT/SIGTERM)");
  app.add_option("--drop-every", drop_every, "drop every Nth sensor frame (link tests)");
  app.add_flag("--no-noise", no_noise, "noise- and bias-free sensors");
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));

  StackConfig config;
  try {
    config = LoadStackConfig(config_path);
  } catch (const ConfigError& e) {
    spdlog::error("{} (file: {})", e.what(), config_path);
    return 2;
  }
  const HwBridgeConfig& hw_cfg = config.hw_bridge;
  if (rate_hz <= 0.0) rate_hz = config.sensors.rate_hz;
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  try {
    std::unique_ptr<hw::PtyDevice> pty;
    std::unique_ptr<hw::Transport> udp;
    hw::Transport* link = nullptr;
    if (transport == "pty") {
      pty = std::make_unique<hw::PtyDevice>();
      link = pty->master();
      if (!pty_link.empty()) {
        unlink(pty_link.c_str());
        if (symlink(pty->slave_path().c_str(), pty_link.c_str()) != 0) {
          throw std::runtime_error("cannot create symlink " + pty_link);
        }
      }
      std::printf("PTY %s\n", pty->slave_path().c_str());
      std::fflush(stdout);
    } else {
      udp = std::make_unique<hw::UdpTransport>(bind_host.empty() ? hw_cfg.device_host : bind_host,
                                               device_port >= 0 ? device_port : hw_cfg.device_port,
                                               host.empty() ? hw_cfg.local_host : host,
                                               host_port >= 0 ? host_port : hw_cfg.local_port);
      link = udp.get();
    }
    spdlog::info("hw_emulator: {} at {} Hz", pty ? "pty " + pty->slave_path() : link->description(),
                 rate_hz);

    hw::ModelBackendOptions backend_options;
    backend_options.noise = !no_noise;
    hw::ModelBackend backend(config.platform, config.actuators, config.sensors, hw_cfg,
                             config.plant_sim.initial_pose, config.plant_sim.initial_velocity,
                             backend_options);
    hw::DeviceEmulator device(&backend);
    hw::StreamParser parser;
    std::array<uint8_t, 4096> rx{};
    std::array<uint8_t, hw::kMaxFrameSize> tx{};

    const auto start = Clock::now();
    // The device clock starts at an arbitrary epoch of its own (power-on),
    // so the host must map it: docs/wire-protocol.md, "Time".
    constexpr uint64_t kDeviceEpochUs = 5'000'000;
    const auto device_now = [&] {
      return kDeviceEpochUs +
             static_cast<uint64_t>(
                 std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start)
                     .count());
    };
    const auto period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
    auto next_tick = start + period;
    uint64_t ticks = 0;
    while (g_stop == 0) {
      if (duration_s > 0.0 && Clock::now() - start > std::chrono::duration<double>(duration_s)) {
        break;
      }
      const auto wait =
          std::chrono::duration_cast<std::chrono::milliseconds>(next_tick - Clock::now());
      const long n =
          link->Receive(rx.data(), rx.size(), static_cast<int>(std::max<int64_t>(0, wait.count())));
      if (n > 0) {
        const auto size = static_cast<std::size_t>(n);
        const auto on_frame = [&](const hw::DecodedFrame& f) {
          if (f.type == hw::FrameType::kCommand) {
            device.OnCommandFrame(f.command, device_now());
          } else {
            device.OnRxError();
          }
        };
        if (link->datagram()) {
          hw::DecodedFrame frame;
          const hw::DecodeStatus s = size > rx.size() ? hw::DecodeStatus::kBadLength
                                                      : hw::DecodeDatagram(rx.data(), size, &frame);
          if (s == hw::DecodeStatus::kOk) {
            on_frame(frame);
          } else {
            device.OnRxError();
          }
        } else {
          parser.Feed(rx.data(), size, on_frame, [&](hw::DecodeStatus) { device.OnRxError(); });
        }
      }
      if (Clock::now() < next_tick) continue;
      const hw::SensorFrame frame = device.Tick(device_now(), 1.0 / rate_hz);
      ++ticks;
      if (drop_every <= 0 || ticks % static_cast<uint64_t>(drop_every) != 0) {
        const std::size_t size = hw::EncodeSensorFrame(frame, tx.data());
        link->Send(tx.data(), size);
      }
      next_tick += period;
      // Fell behind (descheduled): skip, do not burst to catch up.
      if (Clock::now() > next_tick + 10 * period) next_tick = Clock::now() + period;
    }
    if (!pty_link.empty()) unlink(pty_link.c_str());
    spdlog::info("hw_emulator: stopped after {} samples", ticks);
  } catch (const std::exception& e) {
    spdlog::error("hw_emulator: {}", e.what());
    return 1;
  }
  return 0;
}
