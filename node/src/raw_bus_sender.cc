#include "stewart/node/raw_bus_sender.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "stewart/node/lcm_receiver.h"

namespace stewart {
namespace {

void Put32(std::vector<uint8_t>* d, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) d->push_back(static_cast<uint8_t>(v >> shift));
}
void Put16(std::vector<uint8_t>* d, uint16_t v) {
  d->push_back(static_cast<uint8_t>(v >> 8));
  d->push_back(static_cast<uint8_t>(v));
}

}  // namespace

std::vector<uint8_t> LcmShortDatagram(uint32_t seqno, const std::string& channel,
                                      const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> d = {'L', 'C', '0', '2'};
  Put32(&d, seqno);
  d.insert(d.end(), channel.begin(), channel.end());
  d.push_back(0);
  d.insert(d.end(), payload.begin(), payload.end());
  return d;
}

std::vector<uint8_t> LcmFragmentDatagram(uint32_t seqno, uint32_t msg_size,
                                         uint32_t fragment_offset, uint16_t fragment_no,
                                         uint16_t fragments_in_msg, const std::string& channel,
                                         const std::vector<uint8_t>& data) {
  std::vector<uint8_t> d = {'L', 'C', '0', '3'};
  Put32(&d, seqno);
  Put32(&d, msg_size);
  Put32(&d, fragment_offset);
  Put16(&d, fragment_no);
  Put16(&d, fragments_in_msg);
  if (fragment_no == 0) {
    d.insert(d.end(), channel.begin(), channel.end());
    d.push_back(0);
  }
  d.insert(d.end(), data.begin(), data.end());
  return d;
}

std::vector<std::vector<uint8_t>> LcmFragmentedMessage(uint32_t seqno, const std::string& channel,
                                                       const std::vector<uint8_t>& payload,
                                                       size_t max_data_bytes) {
  if (max_data_bytes == 0) throw std::invalid_argument("fragments of 0 bytes");
  const size_t count = std::max<size_t>(1, (payload.size() + max_data_bytes - 1) / max_data_bytes);
  if (count > 65535) throw std::invalid_argument("more than 65535 fragments");
  std::vector<std::vector<uint8_t>> datagrams;
  datagrams.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    const size_t begin = i * max_data_bytes;
    const size_t end = std::min(payload.size(), begin + max_data_bytes);
    datagrams.push_back(LcmFragmentDatagram(
        seqno, static_cast<uint32_t>(payload.size()), static_cast<uint32_t>(begin),
        static_cast<uint16_t>(i), static_cast<uint16_t>(count), channel,
        std::vector<uint8_t>(payload.begin() + static_cast<std::ptrdiff_t>(begin),
                             payload.begin() + static_cast<std::ptrdiff_t>(end))));
  }
  return datagrams;
}

RawBusSender::RawBusSender(const std::string& url) : to_(sizeof(sockaddr_in)) {
  const UdpmAddress address = ParseUdpmUrl(url);
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("socket(): ") + std::strerror(errno));
  const auto ttl = static_cast<unsigned char>(address.ttl);
  setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(address.port));
  inet_aton(address.group.c_str(), &to.sin_addr);
  std::memcpy(to_.data(), &to, sizeof(to));
}

RawBusSender::~RawBusSender() {
  if (fd_ >= 0) close(fd_);
}

bool RawBusSender::Send(const std::vector<uint8_t>& datagram) {
  const ssize_t sent = sendto(fd_, datagram.data(), datagram.size(), 0,
                              reinterpret_cast<const sockaddr*>(to_.data()), sizeof(sockaddr_in));
  return sent == static_cast<ssize_t>(datagram.size());
}

}  // namespace stewart
