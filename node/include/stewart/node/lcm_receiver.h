#pragma once
// The nodes' receive side of LCM's udpm transport, read in the caller's
// thread.
//
// Why not lcm::LCM::subscribe: LCM 1.3.1 reads its socket in a thread of its
// own and hands each message to the caller's thread through a pipe, so every
// message costs two wake-ups. On a small machine the wake-ups dominate one
// hop of the control loop (publish -> receive in another process), and a
// control tick crosses four hops; one socket read in the receiving thread
// costs one (stewart_lcm_hop_bench, docs/performance.md, "LCM hop").
//
// What stays LCM: the wire format (LCM UDP multicast protocol: short "LC02"
// and fragmented "LC03" datagrams), the URL, the multicast group and port,
// lcm-gen types and their decoders. Publishing still goes through
// lcm::LCM::publish (a synchronous sendmsg in the caller's thread). lcm-spy,
// lcm-logger and lcm-logplayer see and feed the same bus.
//
// recv_utime is the kernel's arrival time of the datagram (SO_TIMESTAMP, the
// wall clock in us, as LCM's), so it does not include how long the process
// took to read it.
//
// What differs from lcm::LCM: there is no per-subscription queue that drops
// the newest message at 30; the kernel socket buffer (recv_buf_size in the
// URL, 2 MiB requested by default, capped by net.core.rmem_max) is the
// queue. Channels are exact names, not regular expressions. Each socket has
// a kernel filter (channel_filter.h) so the process is not woken for other
// channels. Linux only.
#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <vector>

namespace stewart {

/// Now on the clock of recv_utime (the wall clock, us): how long a message
/// has waited is ReceiveClockUs() - rbuf->recv_utime.
int64_t ReceiveClockUs();

/// The parts of a udpm:// URL a receiver needs.
struct UdpmAddress {
  std::string group = "239.255.76.67";
  int port = 7667;
  int recv_buf_size = 0;  ///< bytes; 0 = the receiver's default
  int ttl = 0;            ///< multicast TTL of what is sent (LCM's default, 0: this host)
};

/// Parses "udpm://GROUP[:PORT][?key=value&...]" (an empty URL means
/// $LCM_DEFAULT_URL, else LCM's default). Throws std::invalid_argument naming
/// what is wrong for other providers or malformed URLs.
UdpmAddress ParseUdpmUrl(const std::string& url);

struct LcmReceiverCounters {
  int64_t datagrams = 0;              ///< datagrams read from the socket
  int64_t messages = 0;               ///< complete messages handed to a subscriber
  int64_t decode_failures = 0;        ///< subscribed messages whose decode() failed
  int64_t bad_datagrams = 0;          ///< not LCM, truncated, bad fragments
  int64_t incomplete_fragmented = 0;  ///< fragmented messages given up (a fragment lost, too
                                      ///< old, or no room: see lcm_receiver.cc's bounds)
  int64_t orphan_fragments = 0;       ///< later fragments of a message whose first was not kept
  /// Datagrams the kernel dropped since the socket opened (SO_RXQ_OVFL):
  /// those lost unseen because its buffer was full and, while the channel
  /// filter is attached, those the filter skipped (other channels): the
  /// kernel counts both alike. The kernel stamps each datagram with the
  /// drops before it, so a drop shows with the next datagram read.
  int64_t kernel_drops = 0;
};

class LcmReceiver {
 public:
  /// Joins the URL's multicast group on its port. Throws std::runtime_error
  /// with the likely cause (no multicast route) when the socket cannot join.
  explicit LcmReceiver(const std::string& url);
  ~LcmReceiver();
  LcmReceiver(const LcmReceiver&) = delete;
  LcmReceiver& operator=(const LcmReceiver&) = delete;

  /// Calls (handler->*method)(&rbuf, channel, &msg) for every message on
  /// `channel` (exact name), decoded as Msg: the signature of
  /// lcm::LCM::subscribe's member handlers. The message object is reused
  /// between calls.
  template <class Msg, class Handler>
  void Subscribe(const std::string& channel,
                 void (Handler::*method)(const lcm::ReceiveBuffer*, const std::string&, const Msg*),
                 Handler* handler) {
    auto msg = std::make_shared<Msg>();
    AddSubscription(
        channel, [msg, method, handler](const lcm::ReceiveBuffer& rbuf, const std::string& name) {
          if (msg->decode(rbuf.data, 0, static_cast<int>(rbuf.data_size)) < 0) return false;
          (handler->*method)(&rbuf, name, msg.get());
          return true;
        });
  }

  /// Every message on every channel, undecoded (a recorder): the kernel
  /// filter then passes everything. `channel` is the message's channel.
  using RawHandler =
      std::function<void(const lcm::ReceiveBuffer& rbuf, const std::string& channel)>;
  void SubscribeAll(RawHandler handler);

  /// Waits up to timeout_ms (0: do not wait) for the socket, then handles
  /// the datagrams already queued, at most 256 per call (a flood must not
  /// hold the caller's loop; the rest wait for the next call, in order).
  /// Returns the number of messages handed to subscribers (0 on timeout),
  /// or -1 on a receive error.
  int HandleTimeout(int timeout_ms);
  /// The same with a microsecond timeout (ppoll), for loops paced to a
  /// deadline: the wait ends when a datagram arrives, not at the next ms.
  int HandleTimeoutUs(int64_t timeout_us);

  /// The socket, for poll() alongside other descriptors.
  int fd() const { return fd_; }
  const LcmReceiverCounters& counters() const { return counters_; }
  /// False when the kernel filter could not be attached (then every channel
  /// is read and discarded in user space: correct, only slower).
  bool kernel_filter_attached() const { return filter_attached_; }

 private:
  using Dispatch = std::function<bool(const lcm::ReceiveBuffer&, const std::string&)>;
  struct Subscription {
    std::string channel;
    Dispatch dispatch;
  };
  struct Reassembly;

  void AddSubscription(const std::string& channel, Dispatch dispatch);
  void AttachFilter();
  int HandleDatagram(const uint8_t* data, int size, uint32_t sender_ip, uint16_t sender_port,
                     int64_t recv_utime);
  int Deliver(const char* channel, const uint8_t* data, uint32_t size, int64_t recv_utime);
  void DropReassembly(size_t index);  // counted as incomplete
  /// Gives up (and counts) the messages whose first fragment came more than
  /// the reassembly age before `now_us`.
  void DropStaleReassemblies(int64_t now_us);
  bool Subscribed(const std::string& channel) const;

  int fd_ = -1;
  std::vector<Subscription> subscriptions_;
  RawHandler all_;  // set: every channel
  std::string channel_scratch_;
  std::vector<uint8_t> datagram_;
  std::vector<std::unique_ptr<Reassembly>> reassemblies_;  // oldest first
  uint64_t reassembly_bytes_ = 0;                          // their declared sizes
  LcmReceiverCounters counters_;
  bool filter_attached_ = false;
};

}  // namespace stewart
