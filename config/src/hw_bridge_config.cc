#include "stewart/config/hw_bridge_config.h"

namespace stewart {

HwBridgeConfig ParseHwBridgeConfig(const ConfigNode& hw_bridge) {
  HwBridgeConfig h;
  h.transport = hw_bridge.Choice("transport", {"udp", "serial"});
  h.device_host = hw_bridge.String("device_host");
  h.device_port = hw_bridge.Int("device_port");
  h.local_port = hw_bridge.Int("local_port");
  for (const char* key : {"device_port", "local_port"}) {
    const int port = hw_bridge.Int(key);
    if (port < 0 || port > 65535) hw_bridge.Fail(key, "must be a UDP port 0..65535");
  }
  h.serial_device = hw_bridge.String("serial_device");
  h.serial_baud = hw_bridge.Int("serial_baud");
  if (h.serial_baud <= 0) hw_bridge.Fail("serial_baud", "must be positive");
  h.command_timeout_s = hw_bridge.PositiveDouble("command_timeout_s");
  return h;
}

}  // namespace stewart
