#pragma once
#include <cstddef>
#include <cstdint>

namespace stewart::hw {

/// CRC-32/ISO-HDLC (the Ethernet/zlib CRC: poly 0x04C11DB7 reflected,
/// init and xor-out 0xFFFFFFFF). Check value: Crc32("123456789") = 0xCBF43926.
uint32_t Crc32(const uint8_t* data, std::size_t size);

}  // namespace stewart::hw
