// The nodes' LCM receiver: URL parsing, the kernel channel filter on a real
// socket, and end to end against lcm::LCM publishing short and fragmented
// messages, with hostile datagrams in between. Private LCM ports 7800-7807,
// 7889 and 8001.
#include "stewart/node/lcm_receiver.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/channel_filter.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/raw_bus_sender.h"

namespace stewart {
namespace {

TEST(ParseUdpmUrl, ReadsGroupPortAndBufferSize) {
  const UdpmAddress a = ParseUdpmUrl("udpm://239.255.76.67:7801?ttl=0&recv_buf_size=65536");
  EXPECT_EQ(a.group, "239.255.76.67");
  EXPECT_EQ(a.port, 7801);
  EXPECT_EQ(a.recv_buf_size, 65536);
  const UdpmAddress no_port = ParseUdpmUrl("udpm://239.1.2.3");
  EXPECT_EQ(no_port.group, "239.1.2.3");
  EXPECT_EQ(no_port.port, 7667);
  EXPECT_EQ(no_port.recv_buf_size, 0);
}

TEST(ParseUdpmUrl, RejectsWhatItCannotReceive) {
  EXPECT_THROW(ParseUdpmUrl("memq://"), std::invalid_argument);
  EXPECT_THROW(ParseUdpmUrl("udpm://239.255.76.67:notaport"), std::invalid_argument);
  EXPECT_THROW(ParseUdpmUrl("udpm://239.255.76.67:70000"), std::invalid_argument);
  EXPECT_THROW(ParseUdpmUrl("udpm://127.0.0.1:7667"), std::invalid_argument);  // not multicast
  EXPECT_THROW(ParseUdpmUrl("udpm://239.255.76.67:7667?recv_buf_size=-1"), std::invalid_argument);
}

// An LCM short datagram: "LC02", seqno, channel NUL, payload.
std::vector<uint8_t> ShortDatagram(const std::string& channel, size_t payload_bytes) {
  const uint8_t header[8] = {'L', 'C', '0', '2', 0, 0, 0, 7};
  std::vector<uint8_t> d(8 + channel.size() + 1 + payload_bytes, 0xAB);
  std::memcpy(d.data(), header, sizeof(header));
  std::memcpy(d.data() + 8, channel.data(), channel.size());
  d[8 + channel.size()] = 0;
  return d;
}

// Sends datagrams to a loopback socket carrying the filter; returns the
// channel of each datagram that came through (in order).
class FilteredSocket {
 public:
  explicit FilteredSocket(const std::vector<std::string>& channels) {
    rx_ = socket(AF_INET, SOCK_DGRAM, 0);
    tx_ = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    EXPECT_EQ(bind(rx_, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    socklen_t len = sizeof(address_);
    getsockname(rx_, reinterpret_cast<sockaddr*>(&address_), &len);
    std::vector<sock_filter> program = BuildLcmChannelFilter(channels);
    EXPECT_FALSE(program.empty());
    sock_fprog fprog{static_cast<unsigned short>(program.size()), program.data()};
    EXPECT_EQ(setsockopt(rx_, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof(fprog)), 0)
        << std::strerror(errno);
  }
  ~FilteredSocket() {
    close(rx_);
    close(tx_);
  }
  void Send(const std::vector<uint8_t>& d) {
    sendto(tx_, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&address_),
           sizeof(address_));
  }
  // Sizes of the datagrams that passed, after a marker datagram that always
  // passes (not LC02) tells the queue is drained.
  std::vector<size_t> Drain() {
    Send({'E', 'N', 'D', '!', 0, 0, 0, 0});
    std::vector<size_t> sizes;
    uint8_t buf[70000];
    for (;;) {
      pollfd p{rx_, POLLIN, 0};
      if (poll(&p, 1, 1000) <= 0) break;
      const ssize_t n = recv(rx_, buf, sizeof(buf), 0);
      if (n < 0) break;
      if (n == 8 && std::memcmp(buf, "END!", 4) == 0) break;
      sizes.push_back(static_cast<size_t>(n));
    }
    return sizes;
  }

 private:
  int rx_ = -1, tx_ = -1;
  sockaddr_in address_{};
};

TEST(LcmChannelFilter, PassesExactlyTheSubscribedChannelsAndEveryFragment) {
  FilteredSocket s({"STEWART_SENSORS", "A", "STEWART_CMD_SAFE"});
  // Each datagram gets a distinct payload size so the survivors can be named.
  s.Send(ShortDatagram("STEWART_SENSORS", 1));      // pass
  s.Send(ShortDatagram("STEWART_SENSORS_X", 2));    // longer name: drop
  s.Send(ShortDatagram("STEWART_SENSOR", 3));       // a prefix: drop
  s.Send(ShortDatagram("A", 4));                    // pass
  s.Send(ShortDatagram("AB", 5));                   // drop
  s.Send(ShortDatagram("STEWART_CMD_SAFE", 6));     // pass (name length a multiple of 4)
  s.Send(ShortDatagram("STEWART_CMD_NOMINAL", 7));  // drop
  s.Send(ShortDatagram("", 8));                     // drop
  std::vector<uint8_t> fragment = {'L', 'C', '0', '3'};
  fragment.resize(40, 1);
  s.Send(fragment);               // a later fragment (number 257) always passes
  s.Send(ShortDatagram("A", 0));  // a short one at the end of the datagram
  // First fragments name their channel: they pass only for a subscribed one.
  const auto first = [](const std::string& channel, size_t bytes) {
    return LcmFragmentDatagram(9, 100000, 0, 0, 72, channel, std::vector<uint8_t>(bytes, 2));
  };
  s.Send(first("STEWART_SENSORS", 11));                                                  // pass
  s.Send(first("STEWART_SENSORS_X", 12));                                                // drop
  s.Send(first("NOT_OURS", 13));                                                         // drop
  s.Send(first("A", 14));                                                                // pass
  s.Send(LcmFragmentDatagram(9, 100000, 1400, 1, 72, "", std::vector<uint8_t>(15, 2)));  // pass
  s.Send({'X', 'Y', 'Z', '!', 0, 0, 0, 1, 2});  // not LCM: passes, for the receiver to count
  const std::vector<size_t> sizes = s.Drain();
  const std::vector<size_t> expected = {ShortDatagram("STEWART_SENSORS", 1).size(),
                                        ShortDatagram("A", 4).size(),
                                        ShortDatagram("STEWART_CMD_SAFE", 6).size(),
                                        fragment.size(),
                                        ShortDatagram("A", 0).size(),
                                        first("STEWART_SENSORS", 11).size(),
                                        first("A", 14).size(),
                                        20 + 15,
                                        9};
  EXPECT_EQ(sizes, expected);
}

TEST(LcmChannelFilter, DropsEverythingShortWithNoSubscription) {
  FilteredSocket s({});
  s.Send(ShortDatagram("ANY", 10));
  s.Send({'L', 'C', '0', '2'});  // truncated header: the program's load fails, dropped
  EXPECT_TRUE(s.Drain().empty());
}

struct Sink {
  void OnCommand(const lcm::ReceiveBuffer*, const std::string& channel,
                 const force_command_t* msg) {
    channels.push_back(channel);
    seqs.push_back(msg->seq);
  }
  void OnHealth(const lcm::ReceiveBuffer* rbuf, const std::string&, const health_t* msg) {
    health_errors.push_back(msg->last_error);
    health_sizes.push_back(rbuf->data_size);
  }
  std::vector<std::string> channels;
  std::vector<int64_t> seqs;
  std::vector<std::string> health_errors;
  std::vector<uint32_t> health_sizes;
};

void PumpUntil(LcmReceiver* r, const std::function<bool()>& done, double seconds = 3.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done() && std::chrono::steady_clock::now() < end) r->HandleTimeout(20);
}

TEST(LcmReceiver, ReceivesShortAndFragmentedMessagesFromLcmAndOnlyItsChannels) {
  const std::string url = PrivateLcmUrl(7802);
  LcmReceiver receiver(url);
  Sink sink;
  receiver.Subscribe("CMD", &Sink::OnCommand, &sink);
  receiver.Subscribe("BIG", &Sink::OnHealth, &sink);
  EXPECT_TRUE(receiver.kernel_filter_attached());
  auto lcm = MakeLcm(url);

  force_command_t command{};
  for (int i = 0; i < 50; ++i) {
    command.seq = i;
    lcm->publish("CMD", &command);
    lcm->publish("OTHER", &command);  // not subscribed
    lcm->publish("CMDX", &command);   // not subscribed, a longer name
  }
  health_t big{};
  big.name = "big";
  big.last_error = std::string(20000, 'x');  // ~15 fragments of 1400 bytes in LCM 1.3.1
  lcm->publish("BIG", &big);
  PumpUntil(&receiver, [&] { return sink.seqs.size() == 50 && sink.health_errors.size() == 1; });

  ASSERT_EQ(sink.seqs.size(), 50u);
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(sink.seqs[static_cast<size_t>(i)], i);
    EXPECT_EQ(sink.channels[static_cast<size_t>(i)], "CMD");
  }
  ASSERT_EQ(sink.health_errors.size(), 1u);
  EXPECT_EQ(sink.health_errors[0], big.last_error);
  EXPECT_EQ(sink.health_sizes[0], static_cast<uint32_t>(big.getEncodedSize()));
  // The kernel dropped OTHER and CMDX: the socket never saw them.
  EXPECT_EQ(receiver.counters().messages, 51);
  EXPECT_LT(receiver.counters().datagrams, 50 + 20);
  EXPECT_EQ(receiver.counters().decode_failures, 0);
}

// A small message split into fragments (LCM itself sends it whole): the
// receiver reassembles it and hands over exactly the message, so a process
// judges a fragmented message as it judges a short one (stewart_inject
// --fragment-bytes sends the bus faults both ways).
TEST(LcmReceiver, ReassemblesASmallMessageSentInFragments) {
  const std::string url = PrivateLcmUrl(7805);
  LcmReceiver receiver(url);
  Sink sink;
  receiver.Subscribe("CMD", &Sink::OnCommand, &sink);
  RawBusSender bus(url);
  force_command_t command{};
  command.seq = 7;
  command.utime = 123456789;
  std::vector<uint8_t> payload(static_cast<size_t>(command.getEncodedSize()));
  ASSERT_GE(command.encode(payload.data(), 0, static_cast<int>(payload.size())), 0);
  const auto fragments = LcmFragmentedMessage(77, "CMD", payload, 16);
  ASSERT_EQ(fragments.size(), (payload.size() + 15) / 16);
  ASSERT_GE(fragments.size(), 3u);
  for (const auto& d : fragments) ASSERT_TRUE(bus.Send(d));
  PumpUntil(&receiver, [&] { return !sink.seqs.empty(); });
  ASSERT_EQ(sink.seqs.size(), 1u);
  EXPECT_EQ(sink.seqs[0], 7);
  EXPECT_EQ(receiver.counters().messages, 1);
  EXPECT_EQ(receiver.counters().datagrams, static_cast<int64_t>(fragments.size()));
  EXPECT_THROW(LcmFragmentedMessage(1, "CMD", payload, 0), std::invalid_argument);

  // Any size, one fragment short of, at and past a fragment's boundary.
  std::vector<uint32_t> sizes;
  LcmReceiver any(url);
  any.SubscribeAll(
      [&](const lcm::ReceiveBuffer& rbuf, const std::string&) { sizes.push_back(rbuf.data_size); });
  const std::vector<uint32_t> sent = {1, 63, 64, 65, 128, 511};
  for (uint32_t size : sent) {
    for (const auto& d : LcmFragmentedMessage(size, "ANY", std::vector<uint8_t>(size, 0xee), 64))
      ASSERT_TRUE(bus.Send(d));
  }
  PumpUntil(&any, [&] { return sizes.size() == sent.size(); });
  EXPECT_EQ(sizes, sent);
  EXPECT_EQ(any.counters().incomplete_fragmented, 0);
  EXPECT_EQ(any.counters().bad_datagrams, 0);
}

// A message whose fragments stop coming is given up and counted within the
// reassembly age (0.5 s), though no fragment follows to notice it.
TEST(LcmReceiver, CountsAnAbandonedMessageWithoutAnotherFragment) {
  const std::string url = PrivateLcmUrl(7806);
  LcmReceiver receiver(url);
  Sink sink;
  receiver.Subscribe("CMD", &Sink::OnCommand, &sink);
  RawBusSender bus(url);
  const auto fragments = LcmFragmentedMessage(5, "CMD", std::vector<uint8_t>(200, 1), 64);
  ASSERT_TRUE(bus.Send(fragments[0]));
  PumpUntil(&receiver, [&] { return receiver.counters().datagrams == 1; });
  ASSERT_EQ(receiver.counters().datagrams, 1);
  EXPECT_EQ(receiver.counters().incomplete_fragmented, 0);
  PumpUntil(
      &receiver, [&] { return receiver.counters().incomplete_fragmented > 0; }, 2.0);
  EXPECT_EQ(receiver.counters().incomplete_fragmented, 1);
  EXPECT_EQ(receiver.counters().datagrams, 1);
}

int64_t WallUtimeNow() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

TEST(LcmReceiver, SubscribeAllTakesEveryChannelWithKernelArrivalTimes) {
  const std::string url = PrivateLcmUrl(7804);
  LcmReceiver receiver(url);
  std::vector<std::string> channels;
  std::vector<uint32_t> sizes;
  std::vector<int64_t> recv_utimes;
  receiver.SubscribeAll([&](const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
    channels.push_back(channel);
    sizes.push_back(rbuf.data_size);
    recv_utimes.push_back(rbuf.recv_utime);
  });
  EXPECT_FALSE(receiver.kernel_filter_attached());
  auto lcm = MakeLcm(url);
  // Linux turns its receive timestamps on for the whole host when the first
  // socket asks (SO_TIMESTAMP), from a deferred work item: a datagram that
  // arrives before it has run carries no time, and recvmsg stamps it with the
  // time of the read. On an otherwise idle host the first run failed that
  // way now and then (2 of 5 runs 3 s apart; none back to back). A moment
  // for the kernel, then the measured datagrams.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const int64_t before = WallUtimeNow();
  force_command_t command{};
  lcm->publish("A", &command);
  lcm->publish("SOMETHING_ELSE", &command);
  health_t big{};
  big.last_error = std::string(5000, 'y');  // fragmented
  lcm->publish("BIG", &big);
  const int64_t after = WallUtimeNow();
  // Read late, as a batching recorder does: the times are still the arrivals.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  PumpUntil(&receiver, [&] { return channels.size() == 3; });
  const std::vector<std::string> expected = {"A", "SOMETHING_ELSE", "BIG"};
  EXPECT_EQ(channels, expected);
  ASSERT_EQ(sizes.size(), 3u);
  EXPECT_EQ(sizes[0], static_cast<uint32_t>(command.getEncodedSize()));
  EXPECT_EQ(sizes[2], static_cast<uint32_t>(big.getEncodedSize()));
  for (int64_t t : recv_utimes) {
    EXPECT_GE(t, before - 1000);
    EXPECT_LE(t, after + 1000);  // not the read 50 ms later
  }
}

// A receiver that does not read while its socket buffer overflows says how
// many datagrams the kernel dropped (SO_RXQ_OVFL): a recorder reports the
// loss instead of a log silently missing them.
TEST(LcmReceiver, CountsTheDatagramsTheKernelDroppedForAFullBuffer) {
  // recv_buf_size=1: the kernel's minimum buffer, a few datagrams.
  const std::string url = PrivateLcmUrl(7807) + "&recv_buf_size=1";
  LcmReceiver receiver(url);
  int received = 0;
  receiver.SubscribeAll([&](const lcm::ReceiveBuffer&, const std::string&) { ++received; });
  auto lcm = MakeLcm(PrivateLcmUrl(7807));
  force_command_t command{};
  constexpr int kSent = 500;
  for (int i = 0; i < kSent; ++i) lcm->publish("A", &command);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  while (receiver.HandleTimeout(50) > 0) {
  }
  // The kernel stamps each datagram with the drops before it: the count
  // arrives with the first datagram queued after the loss.
  lcm->publish("A", &command);
  while (receiver.HandleTimeout(50) > 0) {
  }
  EXPECT_LT(received, kSent);
  EXPECT_GT(receiver.counters().kernel_drops, 0);
  EXPECT_EQ(received + receiver.counters().kernel_drops, kSent + 1);
  std::printf("[receiver] %d of %d received, %lld dropped by the kernel\n", received, kSent,
              static_cast<long long>(receiver.counters().kernel_drops));
}

// Raw datagrams to the bus, as a broken or hostile sender would send them.
class BusSender {
 public:
  explicit BusSender(int port) : fd_(socket(AF_INET, SOCK_DGRAM, 0)) {
    const unsigned char ttl = 0;
    setsockopt(fd_, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<uint16_t>(port));
    inet_aton("239.255.76.67", &to_.sin_addr);
  }
  ~BusSender() { close(fd_); }
  void Send(const std::vector<uint8_t>& d) {
    sendto(fd_, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof(to_));
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

std::vector<uint8_t> Fragment(uint32_t seqno, uint32_t msg_size, uint32_t offset, uint16_t number,
                              uint16_t count, const std::vector<uint8_t>& body) {
  std::vector<uint8_t> d = {'L', 'C', '0', '3'};
  auto put32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) d.push_back(static_cast<uint8_t>(v >> s));
  };
  put32(seqno);
  put32(msg_size);
  put32(offset);
  d.push_back(static_cast<uint8_t>(number >> 8));
  d.push_back(static_cast<uint8_t>(number));
  d.push_back(static_cast<uint8_t>(count >> 8));
  d.push_back(static_cast<uint8_t>(count));
  d.insert(d.end(), body.begin(), body.end());
  return d;
}

TEST(LcmReceiver, CountsHostileDatagramsAndKeepsWorking) {
  const std::string url = PrivateLcmUrl(7803);
  LcmReceiver receiver(url);
  Sink sink;
  receiver.Subscribe("CMD", &Sink::OnCommand, &sink);
  BusSender bus(7803);
  std::vector<uint8_t> truncated_command = ShortDatagram("CMD", 3);  // too short to decode
  bus.Send(truncated_command);
  bus.Send(Fragment(1, 1u << 30, 0, 0, 2, {'C', 'M', 'D', 0}));       // absurd size
  bus.Send(Fragment(2, 100, 90, 1, 2, std::vector<uint8_t>(20, 0)));  // past the end
  bus.Send(Fragment(3, 100, 0, 3, 2, {}));                            // number >= count
  // Two the kernel filter drops (no channel of ours can be read in them):
  bus.Send(Fragment(4, 100, 0, 0, 2, std::vector<uint8_t>(10, 'Z')));  // unterminated channel
  bus.Send({'L', 'C', '0', '3', 1, 2});                                // truncated header
  // The fragment of a message that never completes, a later fragment of a
  // message whose first never came, then a good message.
  bus.Send(Fragment(5, 1000, 0, 0, 2, {'C', 'M', 'D', 0, 1, 2, 3}));
  bus.Send(Fragment(6, 1000, 500, 1, 2, std::vector<uint8_t>(500, 7)));
  auto lcm = MakeLcm(url);
  force_command_t command{};
  command.seq = 42;
  lcm->publish("CMD", &command);
  PumpUntil(&receiver, [&] { return !sink.seqs.empty(); });
  ASSERT_EQ(sink.seqs.size(), 1u);
  EXPECT_EQ(sink.seqs[0], 42);
  ASSERT_TRUE(receiver.kernel_filter_attached());
  EXPECT_EQ(receiver.counters().decode_failures, 1);
  EXPECT_EQ(receiver.counters().bad_datagrams, 3);
  EXPECT_EQ(receiver.counters().orphan_fragments, 1);
}

// The kernel counts the datagrams its channel filter skips among the
// socket's drops (SO_RXQ_OVFL): a node's count then says nothing of a full
// buffer, and its heartbeat names it for what it is.
TEST(LcmReceiver, TheKernelCountsWhatItsFilterSkippedAmongTheDrops) {
  const std::string url = PrivateLcmUrl(7811);
  LcmReceiver receiver(url);
  Sink sink;
  receiver.Subscribe("CMD", &Sink::OnCommand, &sink);
  ASSERT_TRUE(receiver.kernel_filter_attached());
  auto lcm = MakeLcm(url);
  force_command_t command{};
  constexpr int kOthers = 20;
  for (int i = 0; i < kOthers; ++i) lcm->publish("OTHER", &command);
  command.seq = 7;
  lcm->publish("CMD", &command);
  PumpUntil(&receiver, [&] { return !sink.seqs.empty(); });
  ASSERT_EQ(sink.seqs.size(), 1u);
  // Nothing was lost (the buffer holds a few hundred of these), yet the
  // kernel reports every skipped datagram as dropped.
  EXPECT_EQ(receiver.counters().kernel_drops, kOthers);
  HealthReporter health("test", "HEALTH", 1.0);
  ReportReceiverCounters(receiver, &health);
  EXPECT_EQ(health.counter("rx_kernel_skipped_or_dropped"), kOthers);
  EXPECT_EQ(health.counter("rx_kernel_drops"), 0);
  // A recorder (no filter) reports its count as the buffer's losses.
  LcmReceiver recorder(url);
  recorder.SubscribeAll([](const lcm::ReceiveBuffer&, const std::string&) {});
  ASSERT_FALSE(recorder.kernel_filter_attached());
  HealthReporter recorder_health("recorder", "HEALTH", 1.0);
  ReportReceiverCounters(recorder, &recorder_health);
  EXPECT_EQ(recorder_health.counter("rx_kernel_skipped_or_dropped"), 0);
}

// Minor page faults this thread has taken: pages it touched for the first
// time. Counted by the kernel, so the same on an idle and on a loaded host.
int64_t ThreadMinorFaults() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt;
}

// A flood of first fragments, each declaring a 16 MiB message (1000 per
// second for 2 s, on a subscribed and on an unsubscribed channel), while good
// messages keep coming every 10 ms: no call to HandleTimeout may hold the
// caller's loop for long, every good message arrives, and what was given up
// is counted. (Before the reassembly bounds, each such fragment allocated and
// zeroed its declared 16 MiB: one call read the whole backlog, 0.4-2 s.)
TEST(LcmReceiver, AFloodOfHugeFragmentsNeitherStallsTheLoopNorLosesGoodMessages) {
  const std::string url = PrivateLcmUrl(8001);
  LcmReceiver receiver(url);
  Sink sink;
  receiver.Subscribe("CMD", &Sink::OnCommand, &sink);
  RawBusSender bus(url);
  auto lcm = MakeLcm(url);
  constexpr int kFloodPerSecond = 1000;
  constexpr double kFloodSeconds = 2.0;
  constexpr uint32_t kDeclaredBytes = 16u << 20;
  constexpr int kGoodMessages = 200;  // every 10 ms over the flood
  std::atomic<bool> sending{true};
  std::thread sender([&] {
    const auto start = std::chrono::steady_clock::now();
    const int total = static_cast<int>(kFloodPerSecond * kFloodSeconds);
    force_command_t command{};
    int good = 0;
    for (int i = 0; i < total; ++i) {
      std::this_thread::sleep_until(start +
                                    std::chrono::microseconds(i * 1000000 / kFloodPerSecond));
      const std::string channel = i % 2 == 0 ? "CMD" : "NOT_SUBSCRIBED";
      bus.Send(LcmFragmentDatagram(static_cast<uint32_t>(1000 + i), kDeclaredBytes, 0, 0, 12000,
                                   channel, std::vector<uint8_t>(1200, 0xab)));
      if (i % 10 == 0 && good < kGoodMessages) {
        command.seq = good++;
        lcm->publish("CMD", &command);
      }
    }
    sending = false;
  });
  // What a call costs its caller is the memory it writes: zeroing a
  // declared 16 MiB is 4096 fresh pages, each a page fault the kernel
  // counts. (Its time is shown, not asserted: on a loaded or virtualised
  // host both its wall and its CPU time hold the host's stalls, 20-30 ms.)
  int64_t most_faults_in_a_call = 0;
  double longest_call_wall_ms = 0.0;
  const int64_t faults_before = ThreadMinorFaults();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((sending || sink.seqs.size() < kGoodMessages) &&
         std::chrono::steady_clock::now() < deadline) {
    const int64_t faults0 = ThreadMinorFaults();
    const auto t0 = std::chrono::steady_clock::now();
    receiver.HandleTimeout(5);
    const double wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    most_faults_in_a_call = std::max(most_faults_in_a_call, ThreadMinorFaults() - faults0);
    longest_call_wall_ms = std::max(longest_call_wall_ms, wall_ms);
  }
  const int64_t faults_in_flood = ThreadMinorFaults() - faults_before;
  sender.join();
  std::printf(
      "[flood] HandleTimeout(5 ms) calls: at most %lld page faults in one, %lld in all; longest "
      "%.1f ms of wall time; good %zu/%d; incomplete %lld\n",
      static_cast<long long>(most_faults_in_a_call), static_cast<long long>(faults_in_flood),
      longest_call_wall_ms, sink.seqs.size(), kGoodMessages,
      static_cast<long long>(receiver.counters().incomplete_fragmented));
  EXPECT_EQ(sink.seqs.size(), static_cast<size_t>(kGoodMessages));
  // A control loop must get its thread back within a few periods: no call
  // may write even one declared message's worth of memory (4096 pages), nor
  // the whole flood more than what its fragments carry (1000 x 1200 bytes:
  // 293 pages).
  constexpr int64_t kPagesInADeclaredMessage = kDeclaredBytes / 4096;
  EXPECT_LT(most_faults_in_a_call, kPagesInADeclaredMessage / 16);
  EXPECT_LT(faults_in_flood, kPagesInADeclaredMessage / 4);
  // Every flooded message that started a reassembly was given up, counted.
  EXPECT_GT(receiver.counters().incomplete_fragmented, 0);
}

}  // namespace
}  // namespace stewart
