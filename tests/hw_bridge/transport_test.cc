#include "stewart/hw_bridge/transport.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "stewart/hw_bridge/wire_format.h"

namespace stewart::hw {
namespace {

// UDP ports of this test file: 17610..17619 on 127.0.0.1.
constexpr int kHostPort = 17610;
constexpr int kDevicePort = 17611;

std::vector<uint8_t> CommandBytes(uint32_t seq) {
  CommandFrame c;
  c.seq = seq;
  c.drive = {1, -2, 3, -4, 5, -6};
  c.session = 42;
  std::vector<uint8_t> out(kMaxFrameSize);
  out.resize(EncodeCommandFrame(c, out.data()));
  return out;
}

TEST(UdpTransport, FramesCrossLoopbackBothWays) {
  UdpTransport host("127.0.0.1", kHostPort, "127.0.0.1", kDevicePort);
  UdpTransport device("127.0.0.1", kDevicePort, "127.0.0.1", kHostPort);
  std::array<uint8_t, 2048> buf{};
  for (uint32_t seq = 1; seq <= 50; ++seq) {
    const auto bytes = CommandBytes(seq);
    ASSERT_TRUE(host.Send(bytes.data(), bytes.size()));
    const long n = device.Receive(buf.data(), buf.size(), 1000);
    ASSERT_EQ(n, static_cast<long>(bytes.size()));
    DecodedFrame f;
    ASSERT_EQ(DecodeDatagram(buf.data(), static_cast<std::size_t>(n), &f), DecodeStatus::kOk);
    EXPECT_EQ(f.command.seq, seq);
  }
  SensorFrame s;
  s.seq = 9;
  std::array<uint8_t, kMaxFrameSize> tx{};
  ASSERT_TRUE(device.Send(tx.data(), EncodeSensorFrame(s, tx.data())));
  const long n = host.Receive(buf.data(), buf.size(), 1000);
  DecodedFrame f;
  ASSERT_EQ(DecodeDatagram(buf.data(), static_cast<std::size_t>(n), &f), DecodeStatus::kOk);
  EXPECT_EQ(f.sensor.seq, 9U);
  EXPECT_EQ(host.Receive(buf.data(), buf.size(), 0), 0);  // nothing else queued
}

TEST(UdpTransport, OversizedDatagramReportsItsRealSizeAndForeignSendersAreIgnored) {
  UdpTransport host("127.0.0.1", kHostPort + 2, "127.0.0.1", kDevicePort + 2);
  UdpTransport device("127.0.0.1", kDevicePort + 2, "127.0.0.1", kHostPort + 2);
  UdpTransport stranger("127.0.0.1", kDevicePort + 3, "127.0.0.1", kHostPort + 2);
  std::vector<uint8_t> big(3000, 0xA5);
  ASSERT_TRUE(device.Send(big.data(), big.size()));
  std::array<uint8_t, 256> buf{};
  const long n = host.Receive(buf.data(), buf.size(), 1000);
  EXPECT_EQ(n, 3000);  // > capacity: the caller rejects it as oversized
  const auto bytes = CommandBytes(1);
  ASSERT_TRUE(stranger.Send(bytes.data(), bytes.size()));
  EXPECT_EQ(host.Receive(buf.data(), buf.size(), 1000), 0);
  EXPECT_EQ(host.foreign_datagrams(), 1U);
}

TEST(UdpTransport, BadAddressOrBusyPortThrowsWithTheAddress) {
  EXPECT_THROW(UdpTransport("not-an-ip", kHostPort + 4, "127.0.0.1", 1), std::runtime_error);
  UdpTransport first("127.0.0.1", kHostPort + 5, "127.0.0.1", kDevicePort);
  try {
    UdpTransport second("127.0.0.1", kHostPort + 5, "127.0.0.1", kDevicePort);
    FAIL() << "bound a busy port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(kHostPort + 5)), std::string::npos);
  }
}

TEST(SerialTransport, FramesCrossAPtyPairInArbitraryChunks) {
  PtyDevice pty;
  std::unique_ptr<FdStreamTransport> host = OpenSerial(pty.slave_path(), 921600);
  FdStreamTransport* device = pty.master();
  // Device -> host: 200 sensor frames written back to back with garbage.
  std::vector<uint8_t> stream;
  std::array<uint8_t, kMaxFrameSize> tx{};
  for (uint32_t k = 0; k < 200; ++k) {
    SensorFrame s;
    s.seq = k;
    s.adc.fill(static_cast<uint16_t>(k));
    const std::size_t n = EncodeSensorFrame(s, tx.data());
    stream.insert(stream.end(), tx.begin(), tx.begin() + static_cast<long>(n));
    if (k % 10 == 0) stream.insert(stream.end(), {0x00, 0xA5, 0xFF});
  }
  std::size_t pos = 0;
  StreamParser parser;
  std::vector<uint32_t> seqs;
  std::array<uint8_t, 4096> rx{};
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (seqs.size() < 200 && std::chrono::steady_clock::now() < deadline) {
    if (pos < stream.size()) {
      const std::size_t n = std::min<std::size_t>(333, stream.size() - pos);
      if (device->Send(stream.data() + pos, n)) pos += n;
    }
    const long n = host->Receive(rx.data(), rx.size(), 5);
    ASSERT_GE(n, 0);
    parser.Feed(
        rx.data(), static_cast<std::size_t>(n),
        [&](const DecodedFrame& f) { seqs.push_back(f.sensor.seq); }, [](DecodeStatus) {});
  }
  ASSERT_EQ(seqs.size(), 200U);
  for (uint32_t k = 0; k < 200; ++k) EXPECT_EQ(seqs[k], k);
  EXPECT_EQ(parser.stats().bytes_skipped, 20U * 3U);
  // Host -> device: a command frame, byte-exact (raw mode: no CR/LF mangling,
  // no echo).
  const auto bytes = CommandBytes(42);
  ASSERT_TRUE(host->Send(bytes.data(), bytes.size()));
  std::vector<uint8_t> got;
  while (got.size() < bytes.size() && std::chrono::steady_clock::now() < deadline) {
    const long n = device->Receive(rx.data(), rx.size(), 10);
    ASSERT_GE(n, 0);
    got.insert(got.end(), rx.begin(), rx.begin() + n);
  }
  EXPECT_EQ(got, bytes);
  EXPECT_EQ(host->Receive(rx.data(), rx.size(), 20), 0);  // nothing echoed back
}

TEST(SerialTransport, MissingDeviceOrBadBaudThrows) {
  EXPECT_THROW(OpenSerial("/dev/does-not-exist-hw-bridge", 115200), std::runtime_error);
  PtyDevice pty;
  EXPECT_THROW(OpenSerial(pty.slave_path(), 12345), std::runtime_error);
}

}  // namespace
}  // namespace stewart::hw
