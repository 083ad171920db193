#include "stewart/node/lcm_handle.h"

#include <stdexcept>

namespace stewart {

std::unique_ptr<lcm::LCM> MakeLcm(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw std::runtime_error("cannot open LCM at '" + url +
                             "'. For udpm:// URLs this usually means there is no multicast route: "
                             "run 'ip route add 224.0.0.0/4 dev lo' (as root) or see "
                             "docs/operations.md#troubleshooting");
  }
  return lcm;
}

std::string PrivateLcmUrl(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

}  // namespace stewart
