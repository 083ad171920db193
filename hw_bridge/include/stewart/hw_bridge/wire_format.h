#pragma once
// The device wire protocol, version 2 (docs/wire-protocol.md is the
// specification; this file implements it). Every multi-byte field is
// little-endian. A frame is
//
//   sync 0xA5 0x5A | version u8 | type u8 | payload_length u16 | seq u32 |
//   payload (payload_length bytes) | crc32 u32 over version..payload
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

#include "stewart/common/enum_table.h"

namespace stewart::hw {

constexpr uint8_t kSync0 = 0xA5;
constexpr uint8_t kSync1 = 0x5A;
// 2: the link session (command frames carry it, sensor frames echo it).
constexpr uint8_t kProtocolVersion = 2;
constexpr std::size_t kHeaderSize = 10;
constexpr std::size_t kCrcSize = 4;
constexpr std::size_t kSensorPayloadSize = 72;
constexpr std::size_t kCommandPayloadSize = 24;
constexpr std::size_t kMaxPayloadSize = kSensorPayloadSize;
constexpr std::size_t kMaxFrameSize = kHeaderSize + kMaxPayloadSize + kCrcSize;

enum class FrameType : uint8_t { kSensor = 0x01, kCommand = 0x02 };

/// Full-scale drive: +-kDriveFullScale = +-100 % PWM duty. -32768 is invalid.
constexpr int16_t kDriveFullScale = 32767;
/// Watchdog period the device accepts (us).
constexpr uint32_t kMinWatchdogUs = 1000;
constexpr uint32_t kMaxWatchdogUs = 1000000;

/// Device status bits. Bits 0..4 equal sensor_t.STATUS_* on purpose.
enum DeviceStatus : uint16_t {
  kStatusLegFault = 1U << 0,        ///< a pot reading outside its valid span
  kStatusImuFault = 1U << 1,        ///< IMU not responding or saturated
  kStatusEndstop = 1U << 2,         ///< a leg at a stroke end
  kStatusWatchdog = 1U << 3,        ///< device watchdog expired: drive forced to zero
  kStatusActuatorsOff = 1U << 4,    ///< no command yet, enable bit clear, or e-stop
  kStatusSupplyLow = 1U << 5,       ///< motor supply below its threshold
  kStatusCommandRejected = 1U << 6  ///< the last command frame failed a field check
};

/// Command flags.
enum CommandFlags : uint16_t { kCommandEnable = 1U << 0 };

/// Device -> host, one per device sample period.
struct SensorFrame {
  uint32_t seq = 0;
  uint64_t device_time_us = 0;             ///< device clock at sampling (us)
  std::array<uint16_t, 6> adc{};           ///< leg pot readings (counts)
  std::array<int16_t, 3> gyro_raw{};       ///< IMU rate, {P} axes (LSB)
  std::array<int16_t, 3> accel_raw{};      ///< IMU specific force, {P} axes (LSB)
  uint16_t status = 0;                     ///< DeviceStatus bits
  uint8_t leg_fault_mask = 0;              ///< bit i: leg i faulty
  uint32_t last_command_seq = 0;           ///< seq of the command frame in force
  uint32_t command_age_us = 0;             ///< time since that frame arrived (us)
  std::array<int16_t, 6> applied_drive{};  ///< drive actually applied (after watchdog)
  uint32_t rx_corrupt = 0;                 ///< command frames the device rejected (total)
  uint32_t rx_lost = 0;                    ///< command seq gaps seen by the device (total)
  uint32_t command_session = 0;            ///< link session the device follows (0: none yet)
  uint32_t rx_session_rejected = 0;        ///< command frames of a session not adopted (total)
};

/// Host -> device.
struct CommandFrame {
  uint32_t seq = 0;
  uint32_t watchdog_us = 50000;  ///< zero drive if no new command within this
  std::array<int16_t, 6> drive{};
  uint16_t flags = kCommandEnable;
  /// The sending bridge's link session: random per bridge start, never 0
  /// (docs/wire-protocol.md, "Sessions").
  uint32_t session = 0;
};

/// Whether a command frame asks for no motion: ENABLE clear or zero drive on
/// every leg. Only such a frame may start a session on the device.
bool AsksForNoMotion(const CommandFrame& frame);

enum class DecodeStatus {
  kOk,
  kNeedMore,  ///< stream: not enough bytes yet; datagram: truncated
  kBadSync,
  kBadVersion,
  kBadType,
  kBadLength,  ///< payload length wrong for the type, or oversized datagram
  kBadCrc,
  kBadField,  ///< CRC fine but a field out of range (drive -32768, watchdog, session 0)
};
inline constexpr EnumTable<DecodeStatus, 8> kDecodeStatusNames{{{
    {DecodeStatus::kOk, "ok"},
    {DecodeStatus::kNeedMore, "truncated"},
    {DecodeStatus::kBadSync, "bad_sync"},
    {DecodeStatus::kBadVersion, "bad_version"},
    {DecodeStatus::kBadType, "bad_type"},
    {DecodeStatus::kBadLength, "bad_length"},
    {DecodeStatus::kBadCrc, "bad_crc"},
    {DecodeStatus::kBadField, "bad_field"},
}}};

inline const char* ToString(DecodeStatus status) { return kDecodeStatusNames.Name(status).data(); }

struct DecodedFrame {
  FrameType type = FrameType::kSensor;
  SensorFrame sensor;
  CommandFrame command;
};

/// Encoders return the frame size in bytes (always fits kMaxFrameSize).
std::size_t EncodeSensorFrame(const SensorFrame& frame, uint8_t* out);
std::size_t EncodeCommandFrame(const CommandFrame& frame, uint8_t* out);

/// Decodes one frame starting at data[0]. On kOk, *consumed is its size.
DecodeStatus DecodeFrame(const uint8_t* data, std::size_t size, DecodedFrame* out,
                         std::size_t* consumed);

/// A datagram must hold exactly one frame: trailing bytes are kBadLength.
DecodeStatus DecodeDatagram(const uint8_t* data, std::size_t size, DecodedFrame* out);

/// Counts of what a receiver rejected.
struct RxStats {
  uint64_t frames_ok = 0;
  uint64_t bad_crc = 0;
  uint64_t bad_length = 0;  ///< includes truncated datagrams
  uint64_t bad_header = 0;  ///< version, type
  uint64_t bad_field = 0;
  uint64_t bytes_skipped = 0;  ///< stream bytes discarded while resynchronising

  uint64_t corrupt() const { return bad_crc + bad_length + bad_header + bad_field; }
  void Count(DecodeStatus status);
};

/// Reassembles frames from a byte stream (serial), resynchronising on the
/// sync bytes after garbage or a corrupt frame. Never allocates.
class StreamParser {
 public:
  /// Calls on_frame(const DecodedFrame&) per good frame and
  /// on_error(DecodeStatus) per rejected one.
  template <typename OnFrame, typename OnError>
  void Feed(const uint8_t* data, std::size_t size, OnFrame&& on_frame, OnError&& on_error);

  const RxStats& stats() const { return stats_; }
  void Reset() { size_ = 0; }

 private:
  /// Extracts one frame or error; false when more bytes are needed.
  bool Extract(DecodedFrame* frame, DecodeStatus* status);
  void Drop(std::size_t n);

  std::array<uint8_t, 4 * kMaxFrameSize> buffer_{};
  std::size_t size_ = 0;
  RxStats stats_;
};

template <typename OnFrame, typename OnError>
void StreamParser::Feed(const uint8_t* data, std::size_t size, OnFrame&& on_frame,
                        OnError&& on_error) {
  while (size > 0) {
    const std::size_t n = std::min(size, buffer_.size() - size_);
    for (std::size_t i = 0; i < n; ++i) buffer_[size_ + i] = data[i];
    size_ += n;
    data += n;
    size -= n;
    DecodedFrame frame;
    DecodeStatus status = DecodeStatus::kOk;
    while (Extract(&frame, &status)) {
      if (status == DecodeStatus::kOk) {
        on_frame(static_cast<const DecodedFrame&>(frame));
      } else {
        on_error(status);
      }
    }
  }
}

/// The frames in what one Transport::Receive() returned, whichever the
/// transport: a datagram holds one frame, a byte stream is reassembled.
class FrameReader {
 public:
  explicit FrameReader(bool datagram) : datagram_(datagram) {}

  /// `size` bytes received into a buffer of `capacity` (a datagram longer
  /// than the buffer arrives truncated: kBadLength). Calls on_frame and
  /// on_error as StreamParser::Feed does.
  template <typename OnFrame, typename OnError>
  void Feed(const uint8_t* data, std::size_t size, std::size_t capacity, OnFrame&& on_frame,
            OnError&& on_error) {
    if (!datagram_) {
      parser_.Feed(data, size, on_frame, on_error);
      return;
    }
    DecodedFrame frame;
    const DecodeStatus status =
        size > capacity ? DecodeStatus::kBadLength : DecodeDatagram(data, size, &frame);
    datagram_stats_.Count(status);
    if (status == DecodeStatus::kOk) {
      on_frame(static_cast<const DecodedFrame&>(frame));
    } else {
      on_error(status);
    }
  }

  const RxStats& stats() const { return datagram_ ? datagram_stats_ : parser_.stats(); }

 private:
  bool datagram_;
  StreamParser parser_;
  RxStats datagram_stats_;
};

}  // namespace stewart::hw
