// hw_bridge: the only process that talks to the device. Publishes sensor_t
// on channels.sensors (as plant_sim does) and turns force_command_t from
// channels.command_safe into command frames (docs/wire-protocol.md).
// --bringup: duty commands from <prefix>BRINGUP_DUTY instead, under the
// bridge's own leg guard (docs/hardware.md, "Identify the actuators"); never
// in normal operation.
#include <spdlog/spdlog.h>

#include <memory>

#include "bridge_node.h"
#include "stewart/common/check.h"
#include "stewart/hw_bridge/bringup.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/node/node_main.h"

int main(int argc, char** argv) {
  std::string transport, serial_device, device_host, local_host;
  int device_port = -1, local_port = -1, serial_baud = 0;
  bool bringup = false;
  double bringup_margin_m = -1.0, bringup_speed_cap_mps = -1.0, bringup_end_search_m = -1.0;
  stewart::hw::BringupOptions bringup_options;
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
        app.add_flag("--bringup", bringup,
                     "bring-up mode: per-leg duty commands on <prefix>BRINGUP_DUTY under the "
                     "bridge's leg guard, safe force commands rejected (never in operation)");
        app.add_option("--bringup-margin", bringup_margin_m,
                       "bring-up guard: end zone at either stroke end (m; default "
                       "safety.leg_stroke.margin_m)")
            ->check(CLI::PositiveNumber);
        app.add_option("--bringup-speed-cap", bringup_speed_cap_mps,
                       "bring-up guard: leg speed cap (m/s; default twice the full-duty speed "
                       "of actuators.motor)")
            ->check(CLI::PositiveNumber);
        app.add_option("--bringup-end-search", bringup_end_search_m,
                       "bring-up guard for the pot calibration's stroke-end run: legs may go to "
                       "their end stops and up to this far beyond the nominal ends (m; the pots' "
                       "fault margin widened to match); replaces --bringup-margin")
            ->check(CLI::PositiveNumber);
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
        bringup_options.enabled = bringup;
        bringup_options.guard = stewart::hw::DefaultBringupGuard(
            config.platform.leg_min_length_m, config.platform.leg_max_length_m,
            bringup_margin_m > 0.0 ? bringup_margin_m : config.safety.leg_stroke.margin_m,
            config.actuators.motor);
        if (bringup_speed_cap_mps > 0.0)
          bringup_options.guard.speed_cap_mps = bringup_speed_cap_mps;
        if (bringup_end_search_m > 0.0) {
          if (!bringup) throw stewart::InputError("--bringup-end-search", "goes with --bringup");
          if (bringup_margin_m > 0.0) {
            throw stewart::InputError("--bringup-end-search",
                                      "replaces --bringup-margin: give one");
          }
          const double stroke_m =
              config.platform.leg_max_length_m - config.platform.leg_min_length_m;
          bringup_options.guard = stewart::hw::StrokeEndSearchGuard(
              config.platform.leg_min_length_m, config.platform.leg_max_length_m,
              bringup_end_search_m, bringup_options.guard.speed_cap_mps);
          hw.adc_fault_margin_counts =
              stewart::hw::FaultMarginForSearch(hw, stroke_m, bringup_end_search_m);
        }
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        const std::unique_ptr<stewart::hw::Transport> link =
            stewart::hw::OpenHostTransport(config.hw_bridge);
        if (bringup_options.enabled) {
          const stewart::hw::LegGuardLimits& g = bringup_options.guard;
          spdlog::warn(
              "hw_bridge: BRING-UP MODE: {} drives the legs' duty directly, no safety filter; "
              "guard: end zones {:.4f} m inside the stroke ends (negative: beyond them), leg "
              "speed cap {:.4f} m/s, pots' fault margin {} counts; echo on {}",
              stewart::hw::BringupDutyChannel(config.lcm.channel_prefix, config.lcm.channel_suffix),
              g.margin_m + g.min_length_m - config.platform.leg_min_length_m, g.speed_cap_mps,
              config.hw_bridge.adc_fault_margin_counts,
              stewart::hw::BringupAppliedChannel(config.lcm.channel_prefix,
                                                 config.lcm.channel_suffix));
        }
        spdlog::info("hw_bridge: {} ; sensors -> {}, {} -> commands", link->description(),
                     config.lcm.channels.sensors, config.lcm.channels.command_safe);
        stewart::BridgeNode node(config, lcm, link.get(), bringup_options);
        return node.Run();
      });
}
