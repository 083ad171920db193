// hw_bridge: the only process that talks to the device. Publishes sensor_t
// on channels.sensors (as plant_sim does) and turns force_command_t from
// channels.command_safe into command frames (docs/wire-protocol.md).
#include <spdlog/spdlog.h>

#include <memory>

#include "bridge_node.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/node/node_main.h"

int main(int argc, char** argv) {
  std::string transport, serial_device, device_host, local_host;
  int device_port = -1, local_port = -1, serial_baud = 0;
  return stewart::NodeMain(
      argc, argv, {"hw_bridge", "hw_bridge: the device link behind the plant_sim LCM interface"},
      [&](CLI::App& app) {
        app.add_option("--transport", transport, "udp | serial (default: hw_bridge.transport)")
            ->check(CLI::IsMember({"udp", "serial"}));
        app.add_option("--serial-device", serial_device,
                       "serial device, e.g. a pty from hw_emulator");
        app.add_option("--serial-baud", serial_baud, "serial baud rate");
        app.add_option("--device-host", device_host, "device IPv4 address");
        app.add_option("--device-port", device_port, "device UDP port");
        app.add_option("--local-host", local_host, "local IPv4 address to bind");
        app.add_option("--local-port", local_port, "local UDP port for sensor frames");
      },
      [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
        stewart::HwBridgeConfig& hw = config.hw_bridge;
        if (!transport.empty()) hw.transport = transport;
        if (!serial_device.empty()) hw.serial_device = serial_device;
        if (serial_baud > 0) hw.serial_baud = serial_baud;
        if (!device_host.empty()) hw.device_host = device_host;
        if (device_port >= 0) hw.device_port = device_port;
        if (!local_host.empty()) hw.local_host = local_host;
        if (local_port >= 0) hw.local_port = local_port;
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        const std::unique_ptr<stewart::hw::Transport> link =
            stewart::hw::OpenHostTransport(config.hw_bridge);
        spdlog::info("hw_bridge: {} ; sensors -> {}, {} -> commands", link->description(),
                     config.lcm.channels.sensors, config.lcm.channels.command_safe);
        stewart::BridgeNode node(config, lcm, link.get());
        return node.Run();
      });
}
