#include "stewart/node/lcm_receiver.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "stewart/node/channel_filter.h"

namespace stewart {
namespace {

// LCM UDP multicast protocol (all integers big-endian):
//   short:      "LC02" | seqno u32 | channel NUL | payload
//   fragmented: "LC03" | seqno u32 | msg_size u32 | fragment_offset u32 |
//               fragment_no u16 | fragments_in_msg u16 | [channel NUL, in
//               fragment 0 only] | data
constexpr uint32_t kMagicShort = 0x4c433032;
constexpr uint32_t kMagicLong = 0x4c433033;
constexpr int kShortHeaderBytes = 8;
constexpr int kLongHeaderBytes = 20;
constexpr int kMaxChannelLength = 63;  // LCM_MAX_CHANNEL_NAME_LENGTH
// Far above any message of this stack; a corrupt header must not make us
// allocate LCM's 256 MiB.
constexpr uint32_t kMaxMessageBytes = 16u << 20;
// Bounds on what messages in reassembly may hold, so that a flood of first
// fragments that never complete costs neither memory nor the loop's time:
// at most this many at once, this many declared bytes in all, and a message
// whose fragments have not all come within this long lost one (LCM sends a
// message's fragments back to back).
constexpr size_t kMaxReassemblies = 4;
constexpr uint64_t kMaxReassemblyBytes = uint64_t{32} << 20;
constexpr int64_t kMaxReassemblyAgeUs = 500'000;
// A call reads at most this many datagrams before it returns, so a flood
// cannot keep the caller's loop from its own work; what is left is read at
// the next call, in order.
constexpr int kMaxDatagramsPerCall = 256;
constexpr int kDefaultRecvBufBytes = 2 << 20;
constexpr int kMaxDatagramBytes = 65536;

uint32_t ReadU32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}
uint16_t ReadU16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

// Length of the NUL-terminated channel at p within `size` bytes; -1 if the
// name is unterminated or longer than LCM allows.
int ChannelLength(const uint8_t* p, int size) {
  const int limit = std::min(size, kMaxChannelLength + 1);
  for (int i = 0; i < limit; ++i) {
    if (p[i] == 0) return i;
  }
  return -1;
}

int ParseIntOrThrow(const std::string& text, const std::string& what, const std::string& url) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) {
    throw std::invalid_argument("LCM URL '" + url + "': " + what + " '" + text +
                                "' is not a non-negative integer");
  }
  return static_cast<int>(std::strtol(text.c_str(), nullptr, 10));
}

}  // namespace

struct LcmReceiver::Reassembly {
  uint32_t sender_ip = 0;
  uint16_t sender_port = 0;
  uint32_t seqno = 0;
  std::string channel;  // from fragment 0
  int64_t first_recv_utime = 0;
  uint32_t size = 0;
  // Not zeroed: only what the fragments wrote is ever read, and a message
  // declaring 16 MiB must not cost 16 MiB of writes before its second
  // fragment (the pages are touched only as fragments arrive).
  std::unique_ptr<uint8_t[]> data;
  std::vector<bool> received;
  int remaining = 0;
};

int64_t ReceiveClockUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

UdpmAddress ParseUdpmUrl(const std::string& url_in) {
  std::string url = url_in;
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = env != nullptr && *env != '\0' ? env : "udpm://239.255.76.67:7667";
  }
  const std::string scheme = "udpm://";
  if (url.compare(0, scheme.size(), scheme) != 0) {
    throw std::invalid_argument("LCM URL '" + url +
                                "': the stack's processes need a udpm:// URL (multicast)");
  }
  UdpmAddress a;
  std::string rest = url.substr(scheme.size());
  const size_t question = rest.find('?');
  const std::string query = question == std::string::npos ? "" : rest.substr(question + 1);
  rest = rest.substr(0, question);
  const size_t colon = rest.find(':');
  if (!rest.empty()) a.group = rest.substr(0, colon);
  if (colon != std::string::npos) {
    a.port = ParseIntOrThrow(rest.substr(colon + 1), "port", url);
    if (a.port <= 0 || a.port > 65535) {
      throw std::invalid_argument("LCM URL '" + url + "': port out of range");
    }
  }
  in_addr group{};
  if (inet_aton(a.group.c_str(), &group) == 0 || !IN_MULTICAST(ntohl(group.s_addr))) {
    throw std::invalid_argument("LCM URL '" + url + "': '" + a.group +
                                "' is not a multicast IPv4 address");
  }
  size_t start = 0;
  while (start < query.size()) {
    const size_t amp = query.find('&', start);
    const std::string pair = query.substr(start, amp - start);
    start = amp == std::string::npos ? query.size() : amp + 1;
    const size_t eq = pair.find('=');
    if (pair.substr(0, eq) == "recv_buf_size" && eq != std::string::npos) {
      a.recv_buf_size = ParseIntOrThrow(pair.substr(eq + 1), "recv_buf_size", url);
    }
    if (pair.substr(0, eq) == "ttl" && eq != std::string::npos) {
      a.ttl = ParseIntOrThrow(pair.substr(eq + 1), "ttl", url);
      if (a.ttl > 255) throw std::invalid_argument("LCM URL '" + url + "': ttl above 255");
    }
  }
  return a;
}

LcmReceiver::LcmReceiver(const std::string& url) : datagram_(kMaxDatagramBytes) {
  const UdpmAddress address = ParseUdpmUrl(url);
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("socket(): ") + std::strerror(errno));
  auto fail = [&](const std::string& what) {
    const std::string message = "LCM receiver on '" + url + "': " + what + ": " +
                                std::strerror(errno) +
                                ". For udpm:// URLs this usually means there is no multicast "
                                "route: run 'ip route add 224.0.0.0/4 dev lo' (as root) or see "
                                "docs/operations.md#troubleshooting";
    close(fd_);
    fd_ = -1;
    throw std::runtime_error(message);
  };
  // As lcm::LCM does: every process on the bus binds the same port.
  const int one = 1;
  if (setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)) != 0) fail("SO_REUSEADDR");
  // Arrival times from the kernel (recv_utime), as lcm::LCM takes them.
  setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof(one));
  // How many datagrams the kernel dropped for want of buffer, on each read.
  setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one));
  const int buf = address.recv_buf_size > 0 ? address.recv_buf_size : kDefaultRecvBufBytes;
  setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buf, sizeof(buf));  // capped by rmem_max; best effort
  int granted = 0;
  socklen_t granted_size = sizeof(granted);
  if (getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted, &granted_size) == 0 && granted / 2 < buf) {
    // Above net.core.rmem_max: a process with CAP_NET_ADMIN may still have
    // it (the kernel reports twice the size it was given).
    setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &buf, sizeof(buf));
  }
  sockaddr_in bind_address{};
  bind_address.sin_family = AF_INET;
  bind_address.sin_addr.s_addr = htonl(INADDR_ANY);
  bind_address.sin_port = htons(static_cast<uint16_t>(address.port));
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&bind_address), sizeof(bind_address)) != 0) {
    fail("bind to port " + std::to_string(address.port));
  }
  ip_mreq membership{};
  inet_aton(address.group.c_str(), &membership.imr_multiaddr);
  membership.imr_interface.s_addr = htonl(INADDR_ANY);
  if (setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof(membership)) != 0) {
    fail("joining multicast group " + address.group);
  }
  AttachFilter();  // nothing subscribed yet: only fragments pass
}

LcmReceiver::~LcmReceiver() {
  if (fd_ >= 0) close(fd_);
}

void LcmReceiver::AddSubscription(const std::string& channel, Dispatch dispatch) {
  subscriptions_.push_back(Subscription{channel, std::move(dispatch)});
  AttachFilter();
}

void LcmReceiver::SubscribeAll(RawHandler handler) {
  all_ = std::move(handler);
  const int unused = 0;  // the kernel wants an int-sized option even here
  if (setsockopt(fd_, SOL_SOCKET, SO_DETACH_FILTER, &unused, sizeof(unused)) != 0 &&
      errno != ENOENT) {
    throw std::runtime_error(std::string("LCM receiver: cannot remove the channel filter: ") +
                             std::strerror(errno));
  }
  filter_attached_ = false;
}

void LcmReceiver::AttachFilter() {
  if (all_) return;  // a recorder takes everything
  std::vector<std::string> channels;
  for (const Subscription& s : subscriptions_) channels.push_back(s.channel);
  std::vector<sock_filter> program = BuildLcmChannelFilter(channels);
  filter_attached_ = false;
  if (program.empty()) return;
  sock_fprog fprog{static_cast<unsigned short>(program.size()), program.data()};
  filter_attached_ = setsockopt(fd_, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof(fprog)) == 0;
}

int LcmReceiver::HandleTimeout(int timeout_ms) {
  return HandleTimeoutUs(timeout_ms < 0 ? -1 : int64_t{timeout_ms} * 1000);
}

int LcmReceiver::HandleTimeoutUs(int64_t timeout_us) {
  // A message whose fragments stopped coming is counted when it is given
  // up, not when the next fragment happens to arrive (which may be never).
  if (!reassemblies_.empty()) DropStaleReassemblies(ReceiveClockUs());
  pollfd p{fd_, POLLIN, 0};
  timespec timeout{};
  if (timeout_us > 0) {
    timeout.tv_sec = static_cast<time_t>(timeout_us / 1000000);
    timeout.tv_nsec = static_cast<long>((timeout_us % 1000000) * 1000);
  }
  const int ready = ppoll(&p, 1, timeout_us < 0 ? nullptr : &timeout, nullptr);
  if (ready < 0) return errno == EINTR ? 0 : -1;
  if (ready == 0) return 0;
  int handled = 0;
  for (int read = 0; read < kMaxDatagramsPerCall; ++read) {
    sockaddr_in from{};
    iovec vec{datagram_.data(), datagram_.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(uint32_t))];
    msghdr msg{};
    msg.msg_name = &from;
    msg.msg_namelen = sizeof(from);
    msg.msg_iov = &vec;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof(control);
    const ssize_t size = recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (size < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      if (errno == EINTR) break;
      return handled > 0 ? handled : -1;
    }
    ++counters_.datagrams;
    int64_t recv_utime = -1;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP) {
        timeval tv{};
        std::memcpy(&tv, CMSG_DATA(c), sizeof(tv));
        recv_utime = int64_t{tv.tv_sec} * 1000000 + tv.tv_usec;
      } else if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
        uint32_t dropped = 0;
        std::memcpy(&dropped, CMSG_DATA(c), sizeof(dropped));
        counters_.kernel_drops = dropped;
      }
    }
    if (recv_utime < 0) recv_utime = ReceiveClockUs();
    handled += HandleDatagram(datagram_.data(), static_cast<int>(size), from.sin_addr.s_addr,
                              from.sin_port, recv_utime);
  }
  return handled;
}

int LcmReceiver::HandleDatagram(const uint8_t* data, int size, uint32_t sender_ip,
                                uint16_t sender_port, int64_t recv_utime) {
  if (size < kShortHeaderBytes) {
    ++counters_.bad_datagrams;
    return 0;
  }
  const uint32_t magic = ReadU32(data);
  if (magic == kMagicShort) {
    const int length = ChannelLength(data + kShortHeaderBytes, size - kShortHeaderBytes);
    if (length < 0) {
      ++counters_.bad_datagrams;
      return 0;
    }
    const char* channel = reinterpret_cast<const char*>(data + kShortHeaderBytes);
    const int offset = kShortHeaderBytes + length + 1;
    return Deliver(channel, data + offset, static_cast<uint32_t>(size - offset), recv_utime);
  }
  if (magic != kMagicLong || size < kLongHeaderBytes) {
    ++counters_.bad_datagrams;
    return 0;
  }
  const uint32_t seqno = ReadU32(data + 4);
  const uint32_t msg_size = ReadU32(data + 8);
  const uint32_t fragment_offset = ReadU32(data + 12);
  const uint16_t fragment_no = ReadU16(data + 16);
  const uint16_t fragments = ReadU16(data + 18);
  if (msg_size == 0 || msg_size > kMaxMessageBytes || fragments == 0 || fragment_no >= fragments) {
    ++counters_.bad_datagrams;
    return 0;
  }
  const uint8_t* payload = data + kLongHeaderBytes;
  int payload_size = size - kLongHeaderBytes;
  std::string channel;
  if (fragment_no == 0) {
    const int length = ChannelLength(payload, payload_size);
    if (length < 0) {
      ++counters_.bad_datagrams;
      return 0;
    }
    channel.assign(reinterpret_cast<const char*>(payload), static_cast<size_t>(length));
    payload += length + 1;
    payload_size -= length + 1;
  }
  if (static_cast<uint64_t>(fragment_offset) + static_cast<uint64_t>(payload_size) > msg_size) {
    ++counters_.bad_datagrams;
    return 0;
  }
  // Messages whose fragments stopped coming are given up first.
  DropStaleReassemblies(recv_utime);
  size_t index = reassemblies_.size();
  for (size_t i = 0; i < reassemblies_.size(); ++i) {
    const Reassembly& candidate = *reassemblies_[i];
    if (candidate.sender_ip == sender_ip && candidate.sender_port == sender_port &&
        candidate.seqno == seqno) {
      index = i;
    }
  }
  if (index < reassemblies_.size() && (reassemblies_[index]->size != msg_size ||
                                       reassemblies_[index]->received.size() != fragments)) {
    DropReassembly(index);  // a different message under a reused sequence number
    index = reassemblies_.size();
  }
  if (index == reassemblies_.size()) {
    // As LCM: a message starts with its fragment 0, which names the channel.
    if (fragment_no != 0) {
      ++counters_.orphan_fragments;
      return 0;
    }
    if (!all_ && !Subscribed(channel)) return 0;  // not ours (the kernel filter may be off)
    while (!reassemblies_.empty() && (reassemblies_.size() >= kMaxReassemblies ||
                                      reassembly_bytes_ + msg_size > kMaxReassemblyBytes)) {
      DropReassembly(0);  // the oldest
    }
    auto fresh = std::make_unique<Reassembly>();
    fresh->sender_ip = sender_ip;
    fresh->sender_port = sender_port;
    fresh->seqno = seqno;
    fresh->channel = channel;
    fresh->first_recv_utime = recv_utime;
    fresh->size = msg_size;
    fresh->data.reset(new uint8_t[msg_size]);
    fresh->received.assign(fragments, false);
    fresh->remaining = fragments;
    reassembly_bytes_ += msg_size;
    reassemblies_.push_back(std::move(fresh));
    index = reassemblies_.size() - 1;  // the evictions above moved the end
  }
  Reassembly& r = *reassemblies_[index];
  if (r.received[fragment_no]) return 0;  // a duplicate
  r.received[fragment_no] = true;
  --r.remaining;
  std::memcpy(r.data.get() + fragment_offset, payload, static_cast<size_t>(payload_size));
  if (r.remaining > 0) return 0;
  // Complete: take it out of the list before delivering.
  std::unique_ptr<Reassembly> done = std::move(reassemblies_[index]);
  reassemblies_.erase(reassemblies_.begin() + static_cast<std::ptrdiff_t>(index));
  reassembly_bytes_ -= done->size;
  return Deliver(done->channel.c_str(), done->data.get(), msg_size, recv_utime);
}

void LcmReceiver::DropStaleReassemblies(int64_t now_us) {
  for (size_t i = 0; i < reassemblies_.size();) {
    if (now_us - reassemblies_[i]->first_recv_utime > kMaxReassemblyAgeUs) {
      DropReassembly(i);
    } else {
      ++i;
    }
  }
}

void LcmReceiver::DropReassembly(size_t index) {
  reassembly_bytes_ -= reassemblies_[index]->size;
  reassemblies_.erase(reassemblies_.begin() + static_cast<std::ptrdiff_t>(index));
  ++counters_.incomplete_fragmented;
}

bool LcmReceiver::Subscribed(const std::string& channel) const {
  for (const Subscription& s : subscriptions_) {
    if (s.channel == channel) return true;
  }
  return false;
}

int LcmReceiver::Deliver(const char* channel, const uint8_t* data, uint32_t size,
                         int64_t recv_utime) {
  int handled = 0;
  if (all_) {
    lcm::ReceiveBuffer rbuf{const_cast<uint8_t*>(data), size, recv_utime};
    channel_scratch_.assign(channel);  // reuses its capacity: no allocation per message
    all_(rbuf, channel_scratch_);
    ++handled;
    ++counters_.messages;
  }
  for (Subscription& s : subscriptions_) {
    if (s.channel != channel) continue;
    lcm::ReceiveBuffer rbuf{const_cast<uint8_t*>(data), size, recv_utime};
    if (s.dispatch(rbuf, s.channel)) {
      ++handled;
      ++counters_.messages;
    } else {
      ++counters_.decode_failures;
    }
  }
  return handled;
}

}  // namespace stewart
