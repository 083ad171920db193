// hw_emulator: speaks the device side of docs/wire-protocol.md over UDP or a
// pseudo-terminal, backed by plant_sim's plant and sensor models, with the
// device watchdog. With --lcm-url it also publishes the ground truth on
// lcm.channels.state_truth, as plant_sim does: for evaluation only (a real
// device has no ground truth; the stack never subscribes to it).
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <memory>

#include "stewart/config/config_loader.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "stewart/hw_emulator/plant_backend.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/state_t.hpp"

namespace {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

/// Waits until fd is readable or `deadline` passes, with the timer's
/// precision rather than poll()'s milliseconds: no busy wait before a tick.
bool WaitReadable(int fd, Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now());
  if (left.count() <= 0) return false;
  pollfd pfd{fd, POLLIN, 0};
  timespec timeout{};
  timeout.tv_sec = static_cast<time_t>(left.count() / 1'000'000'000);
  timeout.tv_nsec = static_cast<long>(left.count() % 1'000'000'000);
  return ppoll(&pfd, 1, &timeout, nullptr) > 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace stewart;
  CLI::App app{"hw_emulator: the device side of the wire protocol on plant_sim's plant model"};
  std::string config_path = DefaultConfigPath();
  std::string transport = "udp", pty_link, log_level = "info";
  std::string bind_host, host, lcm_url, channel_suffix;
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
  app.add_option("--lcm-url", lcm_url,
                 "publish the ground truth (state_t, evaluation only) on this LCM URL; "
                 "default: none");
  app.add_option("--channel-suffix", channel_suffix, "suffix of the ground-truth channel");
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
  if (!channel_suffix.empty()) SetChannelSuffix(&config.lcm, channel_suffix);
  const HwBridgeConfig& hw_cfg = config.hw_bridge;
  if (rate_hz <= 0.0) rate_hz = config.sensors.rate_hz;
  const auto period_us = static_cast<uint64_t>(std::llround(1e6 / rate_hz));
  if (period_us == 0) {
    spdlog::error("hw_emulator: rate {} Hz is too high (period < 1 us)", rate_hz);
    return 2;
  }
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
    std::unique_ptr<lcm::LCM> lcm;
    if (!lcm_url.empty()) lcm = MakeLcm(lcm_url);
    spdlog::info("hw_emulator: {} at {} Hz{}",
                 pty ? "pty " + pty->slave_path() : link->description(), rate_hz,
                 lcm ? "; ground truth -> " + config.lcm.channels.state_truth : "");

    hw::PlantBackendOptions backend_options;
    backend_options.noise = !no_noise;
    hw::PlantBackend backend(config, config.plant_sim.initial_pose,
                             config.plant_sim.initial_velocity, backend_options);
    hw::DeviceEmulator device(&backend);
    hw::StreamParser parser;
    std::array<uint8_t, 4096> rx{};
    std::array<uint8_t, hw::kMaxFrameSize> tx{};

    // The device clock starts at an arbitrary epoch of its own (power-on),
    // so the host must map it: docs/wire-protocol.md, "Time". Samples are
    // latched on the exact period grid, as the myRIO's FPGA loop does; the
    // physics runs in device time (DeviceEmulator).
    constexpr uint64_t kDeviceEpochUs = 5'000'000;
    const Clock::time_point start = Clock::now();
    // The host time base of hw_bridge (HostClock): the wall clock read once,
    // advanced by the monotonic clock. Used only to stamp the ground truth.
    const int64_t start_epoch_us = std::chrono::duration_cast<std::chrono::microseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count();
    const auto device_now = [&] {
      return kDeviceEpochUs +
             static_cast<uint64_t>(
                 std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start)
                     .count());
    };
    const auto steady_at = [&](uint64_t device_us) {
      return start + std::chrono::microseconds(device_us - kDeviceEpochUs);
    };
    uint64_t next_tick_us = kDeviceEpochUs + period_us;
    uint64_t ticks = 0;
    uint64_t skipped = 0;
    const auto tick = [&](uint64_t now_us) {
      // Descheduled for a while: skip the samples missed instead of sending a
      // burst; the physics still runs through the gap, in device time.
      if (now_us > next_tick_us + 10 * period_us) {
        const uint64_t missed = (now_us - next_tick_us) / period_us;
        next_tick_us += missed * period_us;
        skipped += missed;
      }
      const hw::SensorFrame frame = device.Tick(next_tick_us);
      ++ticks;
      if (drop_every <= 0 || ticks % static_cast<uint64_t>(drop_every) != 0) {
        const std::size_t size = hw::EncodeSensorFrame(frame, tx.data());
        link->Send(tx.data(), size);
      }
      if (lcm) {
        state_t truth{};
        truth.utime = start_epoch_us + static_cast<int64_t>(next_tick_us - kDeviceEpochUs);
        truth.seq = frame.seq;  // = sensor_t.seq the bridge publishes for this sample
        truth.sample_utime = truth.utime;
        ToArray(backend.q(), truth.q);
        ToArray(backend.qd(), truth.qd);
        truth.status = state_t::STATUS_VALID | state_t::STATUS_GROUND_TRUTH;
        lcm->publish(config.lcm.channels.state_truth, &truth);
      }
      next_tick_us += period_us;
    };
    const auto on_frame = [&](const hw::DecodedFrame& f, uint64_t rx_us) {
      if (f.type == hw::FrameType::kCommand) {
        device.OnCommandFrame(f.command, rx_us);
      } else {
        device.OnRxError();
      }
    };

    while (g_stop == 0) {
      if (duration_s > 0.0 && Clock::now() - start > std::chrono::duration<double>(duration_s)) {
        break;
      }
      if (device_now() >= next_tick_us) {
        tick(device_now());
        continue;
      }
      if (!WaitReadable(link->fd(), steady_at(next_tick_us))) continue;
      const long n = link->Receive(rx.data(), rx.size(), 0);
      if (n <= 0) continue;
      const uint64_t rx_us = device_now();
      // A sample due before this arrival is taken first: the command acts
      // from its arrival on, never on the interval before the sample.
      while (rx_us >= next_tick_us) tick(rx_us);
      const auto size = static_cast<std::size_t>(n);
      if (link->datagram()) {
        hw::DecodedFrame frame;
        const hw::DecodeStatus s = size > rx.size() ? hw::DecodeStatus::kBadLength
                                                    : hw::DecodeDatagram(rx.data(), size, &frame);
        if (s == hw::DecodeStatus::kOk) {
          on_frame(frame, rx_us);
        } else {
          device.OnRxError();
        }
      } else {
        parser.Feed(
            rx.data(), size, [&](const hw::DecodedFrame& f) { on_frame(f, rx_us); },
            [&](hw::DecodeStatus) { device.OnRxError(); });
      }
    }
    if (!pty_link.empty()) unlink(pty_link.c_str());
    spdlog::info("hw_emulator: stopped after {} samples ({} skipped while descheduled)", ticks,
                 skipped);
  } catch (const std::exception& e) {
    spdlog::error("hw_emulator: {}", e.what());
    return 1;
  }
  return 0;
}
