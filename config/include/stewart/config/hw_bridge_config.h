#pragma once
#include <string>

#include "stewart/config/config_node.h"

namespace stewart {

/// `hw_bridge`: transport to the real device (docs/wire-protocol.md).
struct HwBridgeConfig {
  std::string transport = "udp";  ///< udp | serial
  std::string device_host = "127.0.0.1";
  int device_port = 0;
  int local_port = 0;
  std::string serial_device;
  int serial_baud = 0;
  double command_timeout_s = 0.05;
};

HwBridgeConfig ParseHwBridgeConfig(const ConfigNode& hw_bridge);

}  // namespace stewart
