#pragma once
// Raw LCM udpm datagrams onto a bus, as a broken or hostile sender would put
// them there: the fault-injection tool (stewart_inject) and the tests use it
// to check that every receiver bounds what such traffic costs.
//
// The wire format is LCM's UDP multicast protocol (lcm_receiver.cc): short
// "LC02" | seqno | channel NUL | payload, and fragmented "LC03" | seqno |
// msg_size | fragment_offset | fragment_no | fragments_in_msg | [channel NUL
// in fragment 0] | data, all integers big-endian.
#include <cstdint>
#include <string>
#include <vector>

namespace stewart {

/// A short datagram: `payload` on `channel`.
std::vector<uint8_t> LcmShortDatagram(uint32_t seqno, const std::string& channel,
                                      const std::vector<uint8_t>& payload);

/// One fragment of a fragmented message. `channel` is written only into
/// fragment 0 (as LCM does); `data` is the fragment's share of the message.
std::vector<uint8_t> LcmFragmentDatagram(uint32_t seqno, uint32_t msg_size,
                                         uint32_t fragment_offset, uint16_t fragment_no,
                                         uint16_t fragments_in_msg, const std::string& channel,
                                         const std::vector<uint8_t>& data);

/// `payload` on `channel` as a fragmented message, as LCM sends a large one:
/// fragments of at most `max_data_bytes` of the message each (>= 1), in
/// order. A message LCM itself would send whole, split all the same: a
/// receiver must treat both forms alike. At most 65535 fragments
/// (std::invalid_argument beyond).
std::vector<std::vector<uint8_t>> LcmFragmentedMessage(uint32_t seqno, const std::string& channel,
                                                       const std::vector<uint8_t>& payload,
                                                       size_t max_data_bytes);

/// Sends datagrams to the multicast group and port of a udpm:// URL, with
/// TTL 0 unless the URL asks for more (never beyond what the URL allows).
class RawBusSender {
 public:
  /// Throws std::invalid_argument for a URL the receivers could not use, and
  /// std::runtime_error when no socket can be opened.
  explicit RawBusSender(const std::string& url);
  ~RawBusSender();
  RawBusSender(const RawBusSender&) = delete;
  RawBusSender& operator=(const RawBusSender&) = delete;

  /// True when the kernel took the whole datagram.
  bool Send(const std::vector<uint8_t>& datagram);

 private:
  int fd_ = -1;
  std::vector<uint8_t> to_;  // sockaddr_in, kept opaque to keep <netinet/in.h> out
};

}  // namespace stewart
