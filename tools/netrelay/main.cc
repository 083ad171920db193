// stewart_netrelay: joins two LCM multicast groups (two hosts, or two parts
// of a network) through a link made worse on purpose: a one-way delay, a
// jitter and a loss rate, the same both ways. Every datagram heard on one
// group is sent on to the other, fragments included, unchanged; the relay's
// own datagrams are recognised by their source address and never sent back.
//
//   stewart_netrelay --a 'udpm://239.255.77.2:7667?ttl=1' --b 'udpm://239.255.77.1:7667?ttl=1'
//       [--delay-ms 2] [--jitter-ms 1] [--loss 0.01] [--seed 1] [--duration-s 0]
//       [--ready-file PATH]
//
// Hosts on side a use group a, hosts on side b group b (each its own
// --lcm-url). Stopping the relay is a partition; to change the link without
// one, start the new relay, wait for its --ready-file, then stop the old
// one. It prints one line per direction when it stops (SIGINT/SIGTERM or
// --duration-s): offered, delivered, lost, dropped for a full queue, and how
// late it read what the kernel had received (its own stalls).
// docs/operations.md, "Several hosts".
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

#include "stewart/node/impaired_link.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/stop_signal.h"

namespace stewart {
namespace {

int64_t MonotonicUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int64_t RealtimeUs() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return int64_t{t.tv_sec} * 1000000 + t.tv_nsec / 1000;
}

/// How late the relay read what the kernel had already received: the
/// relay's own stalls, told apart from bursts that reached its socket
/// together (a sender or the network stack held them).
struct ReadLag {
  int64_t max_lag_us = 0;     ///< kernel receipt to the relay's read
  int64_t max_lag_at_us = 0;  ///< when (monotonic) the largest lag was seen
  int64_t max_burst = 0;      ///< most datagrams read in one wake-up
};

sockaddr_in GroupAddress(const UdpmAddress& address) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(address.port));
  if (inet_pton(AF_INET, address.group.c_str(), &a.sin_addr) != 1) {
    throw std::invalid_argument("not an IPv4 group: " + address.group);
  }
  return a;
}

/// A socket file descriptor, closed on destruction.
class Socket {
 public:
  Socket() : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0)) {
    if (fd_ < 0) throw std::runtime_error(std::string("socket(): ") + std::strerror(errno));
  }
  ~Socket() { ::close(fd_); }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

void Check(int result, const std::string& what) {
  if (result < 0) throw std::runtime_error(what + ": " + std::strerror(errno));
}

/// One side of the relay: hears its group, sends to it.
struct Side {
  explicit Side(const std::string& url) : address(ParseUdpmUrl(url)), group(GroupAddress(address)) {
    const int one = 1;
    Check(setsockopt(rx.fd(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one), "SO_REUSEADDR");
    // Bound to the group address, the socket hears this group only, not the
    // other side's group on the same port.
    Check(bind(rx.fd(), reinterpret_cast<const sockaddr*>(&group), sizeof group),
          "bind " + address.group + ":" + std::to_string(address.port));
    ip_mreq membership{};
    membership.imr_multiaddr = group.sin_addr;
    membership.imr_interface.s_addr = htonl(INADDR_ANY);
    Check(setsockopt(rx.fd(), IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership),
          "join " + address.group + " (is there a multicast route?)");
    const int rcvbuf = 4 << 20;
    setsockopt(rx.fd(), SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    // The kernel's receipt time of each datagram: the delay counts from it,
    // so a relay that wakes late does not add its lateness to the link's.
    Check(setsockopt(rx.fd(), SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one), "SO_TIMESTAMPNS");

    const auto ttl = static_cast<unsigned char>(address.ttl);
    Check(setsockopt(tx.fd(), IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl), "IP_MULTICAST_TTL");
    // Connected, the sender has a fixed source address and port: what the
    // relay hears back from it is its own and goes no further.
    Check(connect(tx.fd(), reinterpret_cast<const sockaddr*>(&group), sizeof group),
          "connect to " + address.group);
    socklen_t len = sizeof own_source;
    Check(getsockname(tx.fd(), reinterpret_cast<sockaddr*>(&own_source), &len), "getsockname");
  }

  bool IsOwn(const sockaddr_in& from) const {
    return from.sin_port == own_source.sin_port &&
           from.sin_addr.s_addr == own_source.sin_addr.s_addr;
  }

  UdpmAddress address;
  sockaddr_in group;
  Socket rx, tx;
  sockaddr_in own_source{};
  int64_t send_failures = 0;
  ReadLag lag;
};

/// Reads every datagram waiting on `from` and offers the foreign ones to
/// `link`, each at the monotonic time the kernel received it.
void Drain(Side* from, ImpairedLink* link, std::array<uint8_t, 65536>* buffer) {
  int64_t burst = 0;
  for (;;) {
    sockaddr_in source{};
    iovec io{buffer->data(), buffer->size()};
    alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(timespec))> control{};
    msghdr message{};
    message.msg_name = &source;
    message.msg_namelen = sizeof source;
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control.data();
    message.msg_controllen = control.size();
    const ssize_t n = recvmsg(from->rx.fd(), &message, 0);
    if (n < 0) break;  // EAGAIN: nothing more now
    const int64_t now_us = MonotonicUs();
    int64_t lag_us = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec received{};
        std::memcpy(&received, CMSG_DATA(c), sizeof received);
        const int64_t received_us = int64_t{received.tv_sec} * 1000000 + received.tv_nsec / 1000;
        // A wall clock stepped under us gives a lag outside [0, 10 s]: ignored.
        const int64_t lag = RealtimeUs() - received_us;
        if (lag > 0 && lag < 10000000) lag_us = lag;
      }
    }
    ++burst;
    if (lag_us > from->lag.max_lag_us) {
      from->lag.max_lag_us = lag_us;
      from->lag.max_lag_at_us = now_us;
    }
    if (from->IsOwn(source)) continue;
    link->Offer(buffer->data(), static_cast<size_t>(n), now_us - lag_us);
  }
  from->lag.max_burst = std::max(from->lag.max_burst, burst);
}

void Deliver(ImpairedLink* link, Side* to, int64_t now_us) {
  link->DeliverDue(now_us, [to](const std::vector<uint8_t>& datagram) {
    if (send(to->tx.fd(), datagram.data(), datagram.size(), 0) !=
        static_cast<ssize_t>(datagram.size())) {
      ++to->send_failures;
    }
  });
}

void PrintDirection(const char* name, const ImpairedLinkCounters& c, int64_t send_failures,
                    const ReadLag& lag, int64_t start_us) {
  std::printf(
      "stewart_netrelay: %s: offered %lld, delivered %lld, lost %lld, queue full %lld, send "
      "failed %lld, most waiting %lld; read up to %.1f ms after the kernel had it (at %.2f s), "
      "most read in one wake-up %lld\n",
      name, static_cast<long long>(c.offered), static_cast<long long>(c.delivered),
      static_cast<long long>(c.lost), static_cast<long long>(c.overflow),
      static_cast<long long>(send_failures), static_cast<long long>(c.max_queued),
      1e-3 * static_cast<double>(lag.max_lag_us),
      lag.max_lag_at_us > 0 ? 1e-6 * static_cast<double>(lag.max_lag_at_us - start_us) : 0.0,
      static_cast<long long>(lag.max_burst));
}

struct Options {
  std::string url_a, url_b;
  LinkImpairment impairment;
  uint32_t seed = 1;
  double duration_s = 0.0;
  std::string ready_file;  ///< written once both groups are joined
};

int Run(const Options& options) {
  Side a(options.url_a), b(options.url_b);
  if (a.address.group == b.address.group && a.address.port == b.address.port) {
    throw std::invalid_argument("--a and --b are the same group and port: nothing to relay");
  }
  // A different stream of draws per direction, both from the one seed.
  ImpairedLink a_to_b(options.impairment, options.seed),
      b_to_a(options.impairment, options.seed + 1);
  spdlog::info("netrelay: {}:{} <-> {}:{}, delay {} ms + jitter {} ms, loss {}", a.address.group,
               a.address.port, b.address.group, b.address.port, options.impairment.delay_ms,
               options.impairment.jitter_ms, options.impairment.loss);
  std::printf("stewart_netrelay: relaying\n");
  std::fflush(stdout);
  if (!options.ready_file.empty()) {
    // Written whole under another name, then renamed: a reader never sees
    // a half-written file.
    const std::string partial = options.ready_file + ".partial";
    std::ofstream(partial) << "relaying\n";
    if (std::rename(partial.c_str(), options.ready_file.c_str()) != 0) {
      throw std::runtime_error("cannot write --ready-file " + options.ready_file + ": " +
                               std::strerror(errno));
    }
  }
  std::array<uint8_t, 65536> buffer{};
  const int64_t start_us = MonotonicUs();
  const int64_t end_us = options.duration_s > 0.0
                             ? MonotonicUs() + static_cast<int64_t>(options.duration_s * 1e6)
                             : INT64_MAX;
  while (!StopRequested() && MonotonicUs() < end_us) {
    const int64_t now_us = MonotonicUs();
    int64_t wait_us = 100000;  // wake for the stop flag at least this often
    for (const ImpairedLink* link : {&a_to_b, &b_to_a}) {
      if (const auto due = link->NextDueUs())
        wait_us = std::min(wait_us, std::max<int64_t>(*due - now_us, 0));
    }
    std::array<pollfd, 2> fds{{{a.rx.fd(), POLLIN, 0}, {b.rx.fd(), POLLIN, 0}}};
    // poll() counts in ms: round up, and the delivery below is by due time,
    // so a datagram leaves at most ~1 ms after it is due.
    const int ready = poll(fds.data(), fds.size(), static_cast<int>((wait_us + 999) / 1000));
    if (ready < 0 && errno != EINTR) Check(ready, "poll");
    if (fds[0].revents & POLLIN) Drain(&a, &a_to_b, &buffer);
    if (fds[1].revents & POLLIN) Drain(&b, &b_to_a, &buffer);
    const int64_t after_us = MonotonicUs();
    Deliver(&a_to_b, &b, after_us);
    Deliver(&b_to_a, &a, after_us);
  }
  PrintDirection("a->b", a_to_b.counters(), b.send_failures, a.lag, start_us);
  PrintDirection("b->a", b_to_a.counters(), a.send_failures, b.lag, start_us);
  std::fflush(stdout);
  return 0;
}

}  // namespace
}  // namespace stewart

int main(int argc, char** argv) {
  using namespace stewart;
  CLI::App app{"stewart_netrelay: two LCM multicast groups joined through a delayed, lossy link"};
  Options options;
  app.add_option("--a", options.url_a, "side a's LCM URL (udpm://GROUP:PORT?ttl=N)")->required();
  app.add_option("--b", options.url_b, "side b's LCM URL")->required();
  app.add_option("--delay-ms", options.impairment.delay_ms, "one-way delay, each way (ms)")
      ->check(CLI::Range(0.0, 60000.0));
  app.add_option("--jitter-ms", options.impairment.jitter_ms,
                 "plus a uniform draw in [0, jitter] per datagram (ms)")
      ->check(CLI::Range(0.0, 60000.0));
  app.add_option("--loss", options.impairment.loss, "probability a datagram is lost, each way")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--seed", options.seed, "random seed of the loss and jitter draws");
  app.add_option("--duration-s", options.duration_s,
                 "stop after this long (0: until SIGINT/SIGTERM)")
      ->check(CLI::Range(0.0, 1e7));
  app.add_option("--ready-file", options.ready_file,
                 "write this file once both groups are joined and datagrams flow");
  CLI11_PARSE(app, argc, argv);
  InstallStopSignalHandlers();
  try {
    return Run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stewart_netrelay: %s\n", e.what());
    return 2;
  }
}
