// hw_bridge: the only process that talks to the device. Publishes sensor_t
// on channels.sensors (as plant_sim does) and turns force_command_t from
// channels.command_safe into command frames (docs/wire-protocol.md).
#include <poll.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <array>
#include <memory>

#include "stewart/force_command_t.hpp"
#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_bridge/host_clock.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/node_options.h"
#include "stewart/node/stop_signal.h"
#include "stewart/sensor_t.hpp"

namespace stewart {
namespace {

class BridgeNode {
 public:
  BridgeNode(const StackConfig& config, lcm::LCM* lcm, hw::Transport* transport)
      : config_(config),
        lcm_(lcm),
        receiver_(config.lcm.url),
        transport_(transport),
        bridge_(config.hw_bridge, config.platform.leg_min_length_m,
                config.platform.leg_max_length_m - config.platform.leg_min_length_m,
                config.actuators.force_limit_n),
        health_("hw_bridge", config.lcm.channels.health, config.lcm.health_rate_hz) {
    receiver_.Subscribe(config.lcm.channels.command_safe, &BridgeNode::OnCommand, this);
  }

  void Run() {
    std::array<pollfd, 2> fds{pollfd{transport_->fd(), POLLIN, 0},
                              pollfd{receiver_.fd(), POLLIN, 0}};
    while (!StopRequested()) {
      const int ready = poll(fds.data(), fds.size(), 5);
      if (ready > 0 && (fds[0].revents & (POLLIN | POLLERR | POLLHUP)) != 0) ReadDevice();
      if (ready > 0 && (fds[1].revents & POLLIN) != 0) receiver_.HandleTimeout(0);
      UpdateHealth();
    }
    health_.SetState(health_t::STATE_STOPPED);
    health_.MaybePublish(lcm_, true);
  }

 private:
  void ReadDevice() {
    for (int i = 0; i < 64; ++i) {
      const long n = transport_->Receive(rx_.data(), rx_.size(), 0);
      if (n == 0) return;
      if (n < 0) {
        health_.Count("transport_errors");
        return;
      }
      const auto size = static_cast<std::size_t>(n);
      if (transport_->datagram()) {
        hw::DecodedFrame frame;
        const hw::DecodeStatus status = size > rx_.size()
                                            ? hw::DecodeStatus::kBadLength
                                            : hw::DecodeDatagram(rx_.data(), size, &frame);
        datagram_stats_.Count(status);
        if (status == hw::DecodeStatus::kOk) {
          OnFrame(frame);
        } else {
          OnFrameError(status);
        }
      } else {
        parser_.Feed(
            rx_.data(), size, [this](const hw::DecodedFrame& f) { OnFrame(f); },
            [this](hw::DecodeStatus s) { OnFrameError(s); });
      }
    }
  }

  void OnFrameError(hw::DecodeStatus status) { health_.Reject("corrupt_frame", ToString(status)); }

  void OnFrame(const hw::DecodedFrame& frame) {
    if (frame.type != hw::FrameType::kSensor) {
      health_.Reject("unexpected_frame_type");
      return;
    }
    health_.CountIn();
    hw::SensorSample sample;
    if (!bridge_.OnSensorFrame(frame.sensor, clock_.NowMicros(), &sample)) return;
    sensor_t msg{};
    msg.utime = sample.utime;
    msg.seq = sample.seq;
    msg.sample_utime = sample.utime;
    ToArray(sample.leg_length_m, msg.leg_length_m);
    ToArray(sample.gyro_radps, msg.gyro_radps);
    ToArray(sample.accel_mps2, msg.accel_mps2);
    msg.has_orientation = false;
    msg.status = sample.status;
    lcm_->publish(config_.lcm.channels.sensors, &msg);
    health_.CountOut();
    health_.SetStackTime(sample.utime, sample.utime);
    if (bridge_.TickFrameDue()) SendCommand();
  }

  void OnCommand(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
    health_.CountIn();
    const hw::CommandVerdict verdict = bridge_.OnForceCommand(msg->utime, FromArray(msg->force_n));
    if (verdict != hw::CommandVerdict::kAccepted) health_.Reject(ToString(verdict));
    // A non-finite command goes out at once as zero drive, a valid one at once.
    if (verdict == hw::CommandVerdict::kAccepted || verdict == hw::CommandVerdict::kNonFinite) {
      SendCommand();
    }
  }

  void SendCommand() {
    std::array<uint8_t, hw::kMaxFrameSize> frame{};
    const std::size_t size = bridge_.BuildCommandFrame(clock_.NowMicros(), frame.data());
    if (!transport_->Send(frame.data(), size)) health_.Count("send_errors");
  }

  void UpdateHealth() {
    const hw::BridgeCounters& c = bridge_.counters();
    const hw::RxStats& rx = transport_->datagram() ? datagram_stats_ : parser_.stats();
    ReportReceiverCounters(receiver_, &health_);
    health_.SetCounter("sensor_frames", static_cast<int64_t>(c.sensor_frames));
    health_.SetCounter("lost_frames", static_cast<int64_t>(c.lost_frames));
    health_.SetCounter("corrupt_frames", static_cast<int64_t>(rx.corrupt()));
    health_.SetCounter("late_frames", static_cast<int64_t>(c.late_frames));
    health_.SetCounter("reordered_frames", static_cast<int64_t>(c.reordered_frames));
    health_.SetCounter("stream_bytes_skipped", static_cast<int64_t>(rx.bytes_skipped));
    health_.SetCounter("rtt_us_mean", c.rtt_us.mean());
    health_.SetCounter("rtt_us_max", c.rtt_us.max);
    health_.SetCounter("rtt_samples", c.rtt_us.count);
    health_.SetCounter("delay_us_mean", c.delay_us.mean());
    health_.SetCounter("delay_us_max", c.delay_us.max);
    health_.SetCounter("command_frames", static_cast<int64_t>(c.command_frames));
    health_.SetCounter("commands_accepted", static_cast<int64_t>(c.commands_accepted));
    health_.SetCounter("zero_drive_frames", static_cast<int64_t>(c.zero_drive_frames));
    health_.SetCounter("zero_drive", bridge_.last_reason() != hw::DriveReason::kCommand ? 1 : 0);
    health_.SetCounter("force_clamped", static_cast<int64_t>(c.force_clamped));
    health_.SetCounter("duty_clamped", static_cast<int64_t>(c.duty_clamped));
    health_.SetCounter("force_deadzoned", static_cast<int64_t>(c.force_deadzoned));
    health_.SetCounter("leg_fault_samples", static_cast<int64_t>(c.leg_fault_samples));
    health_.SetCounter("imu_fault_samples", static_cast<int64_t>(c.imu_fault_samples));
    health_.SetCounter("device_watchdog_samples", static_cast<int64_t>(c.device_watchdog_samples));
    health_.SetCounter("device_rx_corrupt", static_cast<int64_t>(c.device_rx_corrupt));
    health_.SetCounter("device_rx_lost", static_cast<int64_t>(c.device_rx_lost));

    const int64_t now = clock_.NowMicros();
    const hw::DriveReason reason = bridge_.last_reason();
    const uint16_t device_faults =
        bridge_.last_device_status() &
        (hw::kStatusLegFault | hw::kStatusImuFault | hw::kStatusWatchdog | hw::kStatusSupplyLow);
    if (c.sensor_frames == 0) {
      health_.SetState(health_t::STATE_STARTING);
      health_.SetError("no sensor frame from the device yet (" + transport_->description() + ")");
    } else if (bridge_.LinkDown(now)) {
      health_.SetState(health_t::STATE_FAULT);
      health_.SetError("device link down: no sensor frame for > link_timeout_s");
    } else if (reason != hw::DriveReason::kCommand) {
      health_.SetState(health_t::STATE_DEGRADED);
      health_.SetError(std::string("zero drive: ") + ToString(reason) + " safe command");
    } else if (device_faults != 0) {
      health_.SetState(health_t::STATE_DEGRADED);
      health_.SetError("device status " + std::to_string(bridge_.last_device_status()));
    } else {
      health_.SetState(health_t::STATE_OK);
      health_.SetError("");
    }
    if (health_.MaybePublish(lcm_)) bridge_.ResetWindows();
  }

  const StackConfig& config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  hw::Transport* transport_;
  hw::HwBridge bridge_;
  HealthReporter health_;
  hw::HostClock clock_;
  hw::StreamParser parser_;
  hw::RxStats datagram_stats_;
  std::array<uint8_t, 4096> rx_{};
};

}  // namespace
}  // namespace stewart

int main(int argc, char** argv) {
  using namespace stewart;
  CLI::App app{"hw_bridge: the device link behind the plant_sim LCM interface"};
  NodeOptions options;
  AddNodeOptions(&app, &options);
  std::string transport, serial_device, device_host, local_host;
  int device_port = -1, local_port = -1, serial_baud = 0;
  app.add_option("--transport", transport, "udp | serial (default: hw_bridge.transport)")
      ->check(CLI::IsMember({"udp", "serial"}));
  app.add_option("--serial-device", serial_device, "serial device, e.g. a pty from hw_emulator");
  app.add_option("--serial-baud", serial_baud, "serial baud rate");
  app.add_option("--device-host", device_host, "device IPv4 address");
  app.add_option("--device-port", device_port, "device UDP port");
  app.add_option("--local-host", local_host, "local IPv4 address to bind");
  app.add_option("--local-port", local_port, "local UDP port for sensor frames");
  CLI11_PARSE(app, argc, argv);

  StackConfig config = LoadNodeConfigOrExit(options);

  PrepareForRealTimeIfScheduled("hw_bridge");
  HwBridgeConfig& hw = config.hw_bridge;
  if (!transport.empty()) hw.transport = transport;
  if (!serial_device.empty()) hw.serial_device = serial_device;
  if (serial_baud > 0) hw.serial_baud = serial_baud;
  if (!device_host.empty()) hw.device_host = device_host;
  if (device_port >= 0) hw.device_port = device_port;
  if (!local_host.empty()) hw.local_host = local_host;
  if (local_port >= 0) hw.local_port = local_port;

  InstallStopSignalHandlers();
  try {
    std::unique_ptr<lcm::LCM> lcm = MakeLcm(config.lcm.url);
    std::unique_ptr<hw::Transport> link;
    if (hw.transport == "serial") {
      link = hw::OpenSerial(hw.serial_device, hw.serial_baud);
    } else {
      link = std::make_unique<hw::UdpTransport>(hw.local_host, hw.local_port, hw.device_host,
                                                hw.device_port);
    }
    spdlog::info("hw_bridge: {} ; sensors -> {}, {} -> commands", link->description(),
                 config.lcm.channels.sensors, config.lcm.channels.command_safe);
    BridgeNode node(config, lcm.get(), link.get());
    node.Run();
  } catch (const std::exception& e) {
    spdlog::error("hw_bridge: {}", e.what());
    return 1;
  }
  return 0;
}
