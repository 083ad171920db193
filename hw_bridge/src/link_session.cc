#include "stewart/hw_bridge/link_session.h"

#include <random>

namespace stewart::hw {

uint32_t NewLinkSession() {
  std::random_device entropy;
  std::uniform_int_distribution<uint32_t> draw(1, UINT32_MAX);
  return draw(entropy);
}

}  // namespace stewart::hw
