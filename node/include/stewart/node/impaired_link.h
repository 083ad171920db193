#pragma once
// One direction of a network link made worse on purpose: each datagram is
// lost with a probability, or delivered after a fixed delay plus a uniform
// jitter (so datagrams may overtake each other, as on a real path with
// several queues). stewart_netrelay forwards LCM multicast between two
// groups through two of these (docs/operations.md, "Several hosts"); this
// machine's kernel has no netem qdisc to do it in the network itself.
//
// No sockets here: the caller offers what it received with its receive time
// and sends what DeliverDue hands back, so the rules are unit-tested alone.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <queue>
#include <random>
#include <vector>

namespace stewart {

struct LinkImpairment {
  double delay_ms = 0.0;   ///< one-way delay added to every datagram (ms)
  double jitter_ms = 0.0;  ///< plus a uniform draw in [0, jitter_ms] per datagram (ms)
  double loss = 0.0;       ///< probability that a datagram is dropped, 0..1
};

/// Throws std::invalid_argument naming the field for values a link cannot
/// have (negative or non-finite times, a loss outside 0..1).
void ValidateLinkImpairment(const LinkImpairment& impairment);

struct ImpairedLinkCounters {
  int64_t offered = 0;    ///< datagrams received for this direction
  int64_t lost = 0;       ///< dropped by the loss draw
  int64_t overflow = 0;   ///< dropped because the queue was full (counted, never silent)
  int64_t delivered = 0;  ///< handed to the sender
  int64_t max_queued = 0;
};

class ImpairedLink {
 public:
  /// At most `max_datagrams` / `max_bytes` wait at once; beyond, a datagram
  /// is dropped and counted as overflow.
  ImpairedLink(const LinkImpairment& impairment, uint32_t seed, size_t max_datagrams = 100000,
               size_t max_bytes = size_t{256} << 20);

  /// A datagram received at `now_us` (any monotonic clock, microseconds).
  void Offer(const uint8_t* data, size_t size, int64_t now_us);

  /// The earliest time a queued datagram is due; none when the queue is empty.
  std::optional<int64_t> NextDueUs() const;

  /// Hands every datagram due at `now_us` to `send(const std::vector<uint8_t>&)`,
  /// earliest due first; returns how many.
  template <typename Send>
  int DeliverDue(int64_t now_us, Send&& send) {
    int n = 0;
    while (!queue_.empty() && queue_.top().due_us <= now_us) {
      send(queue_.top().datagram);
      queued_bytes_ -= queue_.top().datagram.size();
      queue_.pop();
      ++counters_.delivered;
      ++n;
    }
    return n;
  }

  const ImpairedLinkCounters& counters() const { return counters_; }

 private:
  struct Pending {
    int64_t due_us;
    uint64_t order;  // arrival order: equal due times leave in it
    std::vector<uint8_t> datagram;
  };
  struct LaterFirst {
    bool operator()(const Pending& a, const Pending& b) const {
      return a.due_us != b.due_us ? a.due_us > b.due_us : a.order > b.order;
    }
  };

  LinkImpairment impairment_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  size_t max_datagrams_, max_bytes_, queued_bytes_ = 0;
  uint64_t next_order_ = 0;
  std::priority_queue<Pending, std::vector<Pending>, LaterFirst> queue_;
  ImpairedLinkCounters counters_;
};

}  // namespace stewart
