#include "stewart/hw_bridge/transport.h"

namespace stewart::hw {

std::unique_ptr<Transport> OpenHostTransport(const HwBridgeConfig& hw) {
  if (hw.transport == "serial") return OpenSerial(hw.serial_device, hw.serial_baud);
  return std::make_unique<UdpTransport>(hw.local_host, hw.local_port, hw.device_host,
                                        hw.device_port);
}

}  // namespace stewart::hw
