#include "stewart/hw_bridge/wire_format.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "stewart/hw_bridge/crc32.h"

namespace stewart::hw {
namespace {

SensorFrame SampleSensorFrame() {
  SensorFrame f;
  f.seq = 0x01020304;
  f.device_time_us = 0x1122334455667788ULL;
  f.adc = {0, 1, 2047, 4095, 65535, 1234};
  f.gyro_raw = {-32767, 0, 32767};
  f.accel_raw = {-1, 8192, -8192};
  f.status = kStatusWatchdog | kStatusEndstop;
  f.leg_fault_mask = 0x21;
  f.last_command_seq = 77;
  f.command_age_us = 999;
  f.applied_drive = {-32767, -1, 0, 1, 32767, 100};
  f.rx_corrupt = 5;
  f.rx_lost = 6;
  f.command_session = 0xCAFEF00D;
  f.rx_session_rejected = 7;
  return f;
}

CommandFrame SampleCommandFrame() {
  CommandFrame f;
  f.seq = 0xFFFFFFFE;
  f.watchdog_us = 50000;
  f.drive = {-32767, -12345, 0, 1, 12345, 32767};
  f.flags = kCommandEnable;
  f.session = 0xA1B2C3D4;
  return f;
}

TEST(Crc32, StandardCheckValue) {
  const uint8_t text[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(Crc32(text, sizeof(text)), 0xCBF43926U);
}

/// Encodes `in` with `encode`, checks the frame's size (`payload_size` plus
/// header and CRC) and decodes it again as one datagram of `type`.
template <typename Frame>
void RoundTrip(const Frame& in, std::size_t (*encode)(const Frame&, uint8_t*),
               std::size_t payload_size, FrameType type, DecodedFrame* out) {
  std::array<uint8_t, kMaxFrameSize> buf{};
  const std::size_t n = encode(in, buf.data());
  EXPECT_EQ(n, kHeaderSize + payload_size + kCrcSize);
  ASSERT_EQ(DecodeDatagram(buf.data(), n, out), DecodeStatus::kOk);
  ASSERT_EQ(out->type, type);
}

TEST(WireFormat, SensorFrameRoundTrip) {
  const SensorFrame in = SampleSensorFrame();
  DecodedFrame out;
  ASSERT_NO_FATAL_FAILURE(
      RoundTrip(in, EncodeSensorFrame, kSensorPayloadSize, FrameType::kSensor, &out));
  const SensorFrame& f = out.sensor;
  EXPECT_EQ(f.seq, in.seq);
  EXPECT_EQ(f.device_time_us, in.device_time_us);
  EXPECT_EQ(f.adc, in.adc);
  EXPECT_EQ(f.gyro_raw, in.gyro_raw);
  EXPECT_EQ(f.accel_raw, in.accel_raw);
  EXPECT_EQ(f.status, in.status);
  EXPECT_EQ(f.leg_fault_mask, in.leg_fault_mask);
  EXPECT_EQ(f.last_command_seq, in.last_command_seq);
  EXPECT_EQ(f.command_age_us, in.command_age_us);
  EXPECT_EQ(f.applied_drive, in.applied_drive);
  EXPECT_EQ(f.rx_corrupt, in.rx_corrupt);
  EXPECT_EQ(f.rx_lost, in.rx_lost);
  EXPECT_EQ(f.command_session, in.command_session);
  EXPECT_EQ(f.rx_session_rejected, in.rx_session_rejected);
}

TEST(WireFormat, CommandFrameRoundTrip) {
  const CommandFrame in = SampleCommandFrame();
  DecodedFrame out;
  ASSERT_NO_FATAL_FAILURE(
      RoundTrip(in, EncodeCommandFrame, kCommandPayloadSize, FrameType::kCommand, &out));
  EXPECT_EQ(out.command.seq, in.seq);
  EXPECT_EQ(out.command.watchdog_us, in.watchdog_us);
  EXPECT_EQ(out.command.drive, in.drive);
  EXPECT_EQ(out.command.flags, in.flags);
  EXPECT_EQ(out.command.session, in.session);
}

TEST(WireFormat, ByteOrderIsLittleEndianAsDocumented) {
  std::array<uint8_t, kMaxFrameSize> buf{};
  EncodeSensorFrame(SampleSensorFrame(), buf.data());
  // docs/wire-protocol.md: sync, version, type, length u16, seq u32, then
  // device_time_us u64 at offset 10.
  EXPECT_EQ(buf[0], 0xA5);
  EXPECT_EQ(buf[1], 0x5A);
  EXPECT_EQ(buf[2], 2);
  EXPECT_EQ(buf[3], 0x01);
  EXPECT_EQ(buf[4], kSensorPayloadSize);
  EXPECT_EQ(buf[5], 0);
  EXPECT_EQ(buf[6], 0x04);
  EXPECT_EQ(buf[9], 0x01);
  EXPECT_EQ(buf[10], 0x88);
  EXPECT_EQ(buf[17], 0x11);
  // adc[0..5] from offset 18; adc[4] = 65535 at offset 26.
  EXPECT_EQ(buf[26], 0xFF);
  EXPECT_EQ(buf[27], 0xFF);
  // Version 2: command_session u32 at offset 74, rx_session_rejected at 78.
  EXPECT_EQ(buf[74], 0x0D);
  EXPECT_EQ(buf[77], 0xCA);
  EXPECT_EQ(buf[78], 7);
  // CRC over bytes 2..81, little-endian at 82: 86 bytes in all.
  EXPECT_EQ(kHeaderSize + kSensorPayloadSize + kCrcSize, 86U);
  const uint32_t crc = Crc32(buf.data() + 2, kHeaderSize - 2 + kSensorPayloadSize);
  EXPECT_EQ(buf[82], crc & 0xFF);
  EXPECT_EQ(buf[85], crc >> 24);
}

TEST(WireFormat, CommandFrameCarriesTheSessionAtOffset30) {
  std::array<uint8_t, kMaxFrameSize> buf{};
  const std::size_t n = EncodeCommandFrame(SampleCommandFrame(), buf.data());
  EXPECT_EQ(n, 38U);
  EXPECT_EQ(buf[2], 2);   // version
  EXPECT_EQ(buf[4], 24);  // payload length
  EXPECT_EQ(buf[28], 0);  // reserved u16
  EXPECT_EQ(buf[29], 0);
  EXPECT_EQ(buf[30], 0xD4);
  EXPECT_EQ(buf[33], 0xA1);
}

TEST(WireFormat, Version1FramesAreRejected) {
  // A device or bridge of the protocol without sessions: a clear bad_version
  // on both sides, never a frame read with the wrong layout.
  std::array<uint8_t, kMaxFrameSize> buf{};
  const std::size_t n = EncodeCommandFrame(SampleCommandFrame(), buf.data());
  buf[2] = 1;
  const uint32_t crc = Crc32(buf.data() + 2, n - 2 - kCrcSize);
  for (std::size_t i = 0; i < 4; ++i) buf[n - 4 + i] = static_cast<uint8_t>(crc >> (8 * i));
  DecodedFrame out;
  EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kBadVersion);
}

TEST(WireFormat, WhichCommandFramesAskForNoMotion) {
  CommandFrame f = SampleCommandFrame();
  EXPECT_FALSE(AsksForNoMotion(f));
  f.flags = 0;  // ENABLE clear: the device applies zero drive
  EXPECT_TRUE(AsksForNoMotion(f));
  f = SampleCommandFrame();
  f.drive.fill(0);
  EXPECT_TRUE(AsksForNoMotion(f));
  f.drive[5] = 1;
  EXPECT_FALSE(AsksForNoMotion(f));
}

TEST(WireFormat, EverySingleBitFlipIsRejected) {
  std::array<uint8_t, kMaxFrameSize> buf{};
  const std::size_t n = EncodeCommandFrame(SampleCommandFrame(), buf.data());
  for (std::size_t byte = 0; byte < n; ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::array<uint8_t, kMaxFrameSize> bad = buf;
      bad[byte] ^= static_cast<uint8_t>(1U << bit);
      DecodedFrame out;
      EXPECT_NE(DecodeDatagram(bad.data(), n, &out), DecodeStatus::kOk)
          << "byte " << byte << " bit " << bit;
    }
  }
}

TEST(WireFormat, TruncatedAndOversizedDatagramsAreRejected) {
  std::array<uint8_t, 2 * kMaxFrameSize> buf{};
  const std::size_t n = EncodeSensorFrame(SampleSensorFrame(), buf.data());
  DecodedFrame out;
  for (std::size_t len = 0; len < n; ++len) {
    EXPECT_EQ(DecodeDatagram(buf.data(), len, &out), DecodeStatus::kNeedMore) << len;
  }
  EXPECT_EQ(DecodeDatagram(buf.data(), n + 1, &out), DecodeStatus::kBadLength);
  // A header announcing a larger payload than the type has.
  std::array<uint8_t, kMaxFrameSize> big = {};
  EncodeCommandFrame(SampleCommandFrame(), big.data());
  big[4] = 200;
  EXPECT_EQ(DecodeDatagram(big.data(), big.size(), &out), DecodeStatus::kBadLength);
}

TEST(WireFormat, OutOfRangeCommandFieldsAreRejected) {
  std::array<uint8_t, kMaxFrameSize> buf{};
  DecodedFrame out;
  CommandFrame f = SampleCommandFrame();
  f.drive[3] = -32768;
  std::size_t n = EncodeCommandFrame(f, buf.data());
  EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kBadField);
  f = SampleCommandFrame();
  f.watchdog_us = kMaxWatchdogUs + 1;
  n = EncodeCommandFrame(f, buf.data());
  EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kBadField);
  f.watchdog_us = kMinWatchdogUs - 1;
  n = EncodeCommandFrame(f, buf.data());
  EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kBadField);
  f = SampleCommandFrame();
  f.session = 0;  // "none": no bridge sends it
  n = EncodeCommandFrame(f, buf.data());
  EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kBadField);
}

TEST(WireFormat, StreamParserResyncsAcrossGarbageAndCorruptFrames) {
  std::vector<uint8_t> stream = {0x00, 0xA5, 0x13, 0xA5};  // garbage with false syncs
  std::array<uint8_t, kMaxFrameSize> buf{};
  std::vector<uint32_t> expected;
  for (uint32_t k = 0; k < 20; ++k) {
    SensorFrame f = SampleSensorFrame();
    f.seq = k;
    const std::size_t n = EncodeSensorFrame(f, buf.data());
    if (k % 5 == 3) {
      buf[20] ^= 0x40;  // corrupt: must be counted and skipped
    } else {
      expected.push_back(k);
    }
    stream.insert(stream.end(), buf.begin(), buf.begin() + static_cast<long>(n));
    if (k % 4 == 1) stream.insert(stream.end(), {0xA5, 0x5A, 0x07});  // a broken header
  }
  StreamParser parser;
  std::vector<uint32_t> got;
  int errors = 0;
  // Byte-sized and odd-sized chunks, as a UART delivers them.
  std::size_t pos = 0;
  std::size_t chunk = 1;
  while (pos < stream.size()) {
    const std::size_t n = std::min(chunk, stream.size() - pos);
    parser.Feed(
        stream.data() + pos, n, [&](const DecodedFrame& f) { got.push_back(f.sensor.seq); },
        [&](DecodeStatus) { ++errors; });
    pos += n;
    chunk = chunk % 37 + 1;
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(parser.stats().frames_ok, expected.size());
  EXPECT_EQ(parser.stats().bad_crc, 4U);
  EXPECT_GE(errors, 4 + 5);  // 4 corrupt frames, 5 broken headers
}

TEST(FrameReader, DatagramsDecodeWholeAndStreamsReassemble) {
  std::array<uint8_t, kMaxFrameSize> buf{};
  const std::size_t n = EncodeSensorFrame(SampleSensorFrame(), buf.data());
  std::vector<uint32_t> got;
  std::vector<DecodeStatus> errors;
  const auto on_frame = [&](const DecodedFrame& f) { got.push_back(f.sensor.seq); };
  const auto on_error = [&](DecodeStatus s) { errors.push_back(s); };

  FrameReader datagrams(true);
  datagrams.Feed(buf.data(), n, buf.size(), on_frame, on_error);
  datagrams.Feed(buf.data(), n - 1, buf.size(), on_frame, on_error);           // truncated
  datagrams.Feed(buf.data(), buf.size() + 1, buf.size(), on_frame, on_error);  // too long
  EXPECT_EQ(got, std::vector<uint32_t>{SampleSensorFrame().seq});
  EXPECT_EQ(errors.size(), 2U);
  EXPECT_EQ(errors.back(), DecodeStatus::kBadLength);
  EXPECT_EQ(datagrams.stats().frames_ok, 1U);
  EXPECT_EQ(datagrams.stats().corrupt(), 2U);

  got.clear();
  errors.clear();
  FrameReader stream(false);
  stream.Feed(buf.data(), 5, buf.size(), on_frame, on_error);  // half a frame: nothing yet
  EXPECT_TRUE(got.empty());
  stream.Feed(buf.data() + 5, n - 5, buf.size(), on_frame, on_error);
  EXPECT_EQ(got, std::vector<uint32_t>{SampleSensorFrame().seq});
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(stream.stats().frames_ok, 1U);
}

// Random bytes, random mutations of valid frames, random lengths: always a
// clean verdict, never a crash, never a frame from pure noise.
TEST(WireFormat, FuzzRandomBuffersAreRejectedAndCounted) {
  std::mt19937 rng(1234);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 3 * kMaxFrameSize);
  std::array<uint8_t, 3 * kMaxFrameSize> buf{};
  std::array<uint8_t, kMaxFrameSize> valid{};
  const std::size_t valid_n = EncodeSensorFrame(SampleSensorFrame(), valid.data());
  StreamParser parser;
  RxStats datagram_stats;
  uint64_t accepted_noise = 0;
  constexpr int kBuffers = 100000;
  for (int i = 0; i < kBuffers; ++i) {
    const std::size_t n = length(rng);
    for (std::size_t k = 0; k < n; ++k) buf[k] = static_cast<uint8_t>(byte(rng));
    if (i % 2 == 0 && n >= valid_n) {
      // A valid frame with 1..4 random byte changes: at least one changes.
      std::copy(valid.begin(), valid.begin() + static_cast<long>(valid_n), buf.begin());
      const int changes = 1 + i % 4;
      bool changed = false;
      for (int c = 0; c < changes; ++c) {
        const std::size_t at = static_cast<std::size_t>(byte(rng)) % valid_n;
        const auto v = static_cast<uint8_t>(byte(rng));
        changed = changed || v != buf[at];
        buf[at] = v;
      }
      if (!changed) buf[5] ^= 1;
    } else if (n >= 2) {
      buf[0] = kSync0;  // give the noise a fair chance past the sync check
      buf[1] = kSync1;
    }
    DecodedFrame out;
    const DecodeStatus s = DecodeDatagram(buf.data(), n, &out);
    datagram_stats.Count(s);
    if (s == DecodeStatus::kOk) ++accepted_noise;
    parser.Feed(
        buf.data(), n, [&](const DecodedFrame&) { ++accepted_noise; }, [](DecodeStatus) {});
  }
  EXPECT_EQ(accepted_noise, 0U);
  EXPECT_EQ(datagram_stats.frames_ok, 0U);
  EXPECT_EQ(datagram_stats.corrupt(), static_cast<uint64_t>(kBuffers));
  EXPECT_GT(parser.stats().corrupt() + parser.stats().bytes_skipped, 0U);
  // The parser still works after all that noise.
  parser.Reset();
  int good = 0;
  parser.Feed(
      valid.data(), valid_n, [&](const DecodedFrame&) { ++good; }, [](DecodeStatus) {});
  EXPECT_EQ(good, 1);
}

}  // namespace
}  // namespace stewart::hw
