#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "stewart/hw_bridge/transport.h"

namespace stewart::hw {
namespace {

sockaddr_in Address(const std::string& host, int port, const std::string& what) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &a.sin_addr) != 1) {
    throw std::runtime_error(what + " '" + host + "' is not an IPv4 address");
  }
  return a;
}

}  // namespace

UdpTransport::UdpTransport(const std::string& bind_host, int bind_port,
                           const std::string& peer_host, int peer_port)
    : FdTransport(-1, "udp " + bind_host + ":" + std::to_string(bind_port) + " <-> " + peer_host +
                          ":" + std::to_string(peer_port)) {
  const sockaddr_in local = Address(bind_host, bind_port, "bind host");
  const sockaddr_in peer = Address(peer_host, peer_port, "peer host");
  peer_addr_ = peer.sin_addr.s_addr;
  peer_port_ = peer.sin_port;
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("socket(): " + std::string(std::strerror(errno)));
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&local), sizeof(local)) != 0) {
    const std::string err = std::strerror(errno);  // FdTransport closes fd_
    throw std::runtime_error("cannot bind " + bind_host + ":" + std::to_string(bind_port) + ": " +
                             err);
  }
}

bool UdpTransport::Send(const uint8_t* data, std::size_t size) {
  sockaddr_in peer{};
  peer.sin_family = AF_INET;
  peer.sin_addr.s_addr = peer_addr_;
  peer.sin_port = peer_port_;
  const ssize_t n =
      sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&peer), sizeof(peer));
  return n == static_cast<ssize_t>(size);
}

long UdpTransport::Receive(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  const int ready = poll(&p, 1, timeout_ms);
  if (ready < 0) return errno == EINTR ? 0 : -1;
  if (ready == 0) return 0;
  sockaddr_in from{};
  socklen_t from_len = sizeof(from);
  // MSG_TRUNC: an oversized datagram reports its real size, so the decoder
  // rejects it as oversized instead of seeing a cut-off frame.
  const ssize_t n =
      recvfrom(fd_, buffer, capacity, MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &from_len);
  if (n < 0) return (errno == EINTR || errno == EAGAIN) ? 0 : -1;
  if (from.sin_addr.s_addr != peer_addr_ || from.sin_port != peer_port_) {
    ++foreign_;
    return 0;
  }
  return static_cast<long>(n);
}

}  // namespace stewart::hw
