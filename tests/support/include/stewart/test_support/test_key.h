#pragma once
// A message-authentication key for tests of the signed channels.
#include <cstdint>
#include <vector>

namespace stewart::test {

/// A 32-byte key that differs for every `seed`.
inline std::vector<uint8_t> TestKey(uint8_t seed) {
  std::vector<uint8_t> key(32);
  for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<uint8_t>(seed + 7 * i);
  return key;
}

}  // namespace stewart::test
