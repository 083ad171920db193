#include "stewart/node/channel_filter.h"

#include <algorithm>
#include <cstdint>

namespace stewart {
namespace {

// A socket filter on a UDP socket sees the datagram from the UDP header.
constexpr uint32_t kUdpHeaderBytes = 8;
// LCM udpm short message: magic "LC02" (4 bytes), sequence number (4), then
// the channel name with its NUL, then the payload.
constexpr uint32_t kMagicOffset = kUdpHeaderBytes;
constexpr uint32_t kChannelOffset = kUdpHeaderBytes + 8;
constexpr uint32_t kMagicShort = 0x4c433032;  // "LC02"
// Fragmented: "LC03" (4), seqno (4), msg_size (4), fragment_offset (4),
// fragment_no (2), fragments_in_msg (2), then in fragment 0 the channel.
constexpr uint32_t kMagicFragment = 0x4c433033;  // "LC03"
constexpr uint32_t kFragmentNumberOffset = kUdpHeaderBytes + 16;
constexpr uint32_t kFragmentChannelOffset = kUdpHeaderBytes + 20;
constexpr uint32_t kAccept = 0xffffffffu;  // keep the whole datagram
constexpr uint32_t kDrop = 0;

sock_filter Statement(uint16_t code, uint32_t k) { return sock_filter{code, 0, 0, k}; }
sock_filter Jump(uint16_t code, uint32_t k, uint8_t jt, uint8_t jf) {
  return sock_filter{code, jt, jf, k};
}

// Big-endian value of `size` bytes at `p`, as BPF_ABS loads it.
uint32_t BigEndian(const unsigned char* p, int size) {
  uint32_t v = 0;
  for (int i = 0; i < size; ++i) v = (v << 8) | p[i];
  return v;
}

// Appends, for each of `channels` (shortest first), the comparison of the
// NUL-terminated name at `offset` with an accept on a match, then a drop.
// False when a block is too long for BPF's 8-bit jumps.
bool AppendChannelBlocks(const std::vector<std::string>& channels, uint32_t offset,
                         std::vector<sock_filter>* program) {
  for (const std::string& name : channels) {
    // name + NUL, compared in 4-, then 2-, then 1-byte loads.
    std::vector<unsigned char> bytes(name.begin(), name.end());
    bytes.push_back(0);
    std::vector<sock_filter> block;
    size_t at = 0;
    while (at < bytes.size()) {
      const size_t left = bytes.size() - at;
      const int size = left >= 4 ? 4 : (left >= 2 ? 2 : 1);
      const uint16_t width = size == 4 ? BPF_W : (size == 2 ? BPF_H : BPF_B);
      block.push_back(Statement(BPF_LD | width | BPF_ABS, offset + static_cast<uint32_t>(at)));
      block.push_back(Jump(BPF_JMP | BPF_JEQ | BPF_K, BigEndian(bytes.data() + at, size), 0, 0));
      at += static_cast<size_t>(size);
    }
    block.push_back(Statement(BPF_RET | BPF_K, kAccept));
    // Every mismatch jumps past this block's accept, to the next name.
    for (size_t i = 0; i < block.size(); ++i) {
      if (BPF_CLASS(block[i].code) == BPF_JMP) {
        const size_t skip = block.size() - 1 - i;  // instructions after this one in the block
        if (skip > 255) return false;
        block[i].jf = static_cast<uint8_t>(skip);
      }
    }
    program->insert(program->end(), block.begin(), block.end());
  }
  program->push_back(Statement(BPF_RET | BPF_K, kDrop));
  return true;
}

}  // namespace

std::vector<sock_filter> BuildLcmChannelFilter(std::vector<std::string> channels) {
  // Shortest names first: an absolute load past the end of the datagram
  // ends the program with "drop", so no comparison may read further than
  // the name of the datagram's own channel (which it carries in full).
  std::sort(channels.begin(), channels.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  channels.erase(std::unique(channels.begin(), channels.end()), channels.end());

  // Short messages by their channel; the first fragment of a fragmented
  // message by its channel too (a flood of fragments on another channel
  // never wakes the process); later fragments and anything not LCM pass
  // (the receiver drops a fragment whose first it did not keep, and counts
  // what is not LCM).
  std::vector<sock_filter> short_section;
  if (!AppendChannelBlocks(channels, kChannelOffset, &short_section)) return {};
  if (short_section.size() > 255) return {};
  std::vector<sock_filter> program;
  program.push_back(Statement(BPF_LD | BPF_W | BPF_ABS, kMagicOffset));
  program.push_back(
      Jump(BPF_JMP | BPF_JEQ | BPF_K, kMagicShort, 0, static_cast<uint8_t>(short_section.size())));
  program.insert(program.end(), short_section.begin(), short_section.end());
  program.push_back(Jump(BPF_JMP | BPF_JEQ | BPF_K, kMagicFragment, 1, 0));
  program.push_back(Statement(BPF_RET | BPF_K, kAccept));  // not LCM: counted by the receiver
  program.push_back(Statement(BPF_LD | BPF_H | BPF_ABS, kFragmentNumberOffset));
  program.push_back(Jump(BPF_JMP | BPF_JEQ | BPF_K, 0, 1, 0));
  program.push_back(Statement(BPF_RET | BPF_K, kAccept));  // a later fragment: no channel in it
  if (!AppendChannelBlocks(channels, kFragmentChannelOffset, &program)) return {};
  return program;
}

}  // namespace stewart
