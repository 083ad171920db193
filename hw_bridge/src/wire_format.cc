#include "stewart/hw_bridge/wire_format.h"

#include <algorithm>
#include <cstring>

#include "stewart/hw_bridge/crc32.h"

namespace stewart::hw {
namespace {

// Explicit little-endian (de)serialisation: the wire order never depends on
// the host's.
class Writer {
 public:
  explicit Writer(uint8_t* out) : p_(out) {}
  void U8(uint8_t v) { *p_++ = v; }
  void U16(uint16_t v) {
    U8(static_cast<uint8_t>(v));
    U8(static_cast<uint8_t>(v >> 8));
  }
  void U32(uint32_t v) {
    U16(static_cast<uint16_t>(v));
    U16(static_cast<uint16_t>(v >> 16));
  }
  void U64(uint64_t v) {
    U32(static_cast<uint32_t>(v));
    U32(static_cast<uint32_t>(v >> 32));
  }
  void I16(int16_t v) { U16(static_cast<uint16_t>(v)); }
  uint8_t* pos() const { return p_; }

 private:
  uint8_t* p_;
};

class Reader {
 public:
  explicit Reader(const uint8_t* in) : p_(in) {}
  uint8_t U8() { return *p_++; }
  uint16_t U16() {
    const uint16_t lo = U8();
    return static_cast<uint16_t>(lo | (static_cast<uint16_t>(U8()) << 8));
  }
  uint32_t U32() {
    const uint32_t lo = U16();
    return lo | (static_cast<uint32_t>(U16()) << 16);
  }
  uint64_t U64() {
    const uint64_t lo = U32();
    return lo | (static_cast<uint64_t>(U32()) << 32);
  }
  int16_t I16() { return static_cast<int16_t>(U16()); }

 private:
  const uint8_t* p_;
};

std::size_t PayloadSize(uint8_t type) {
  switch (static_cast<FrameType>(type)) {
    case FrameType::kSensor:
      return kSensorPayloadSize;
    case FrameType::kCommand:
      return kCommandPayloadSize;
  }
  return 0;
}

std::size_t Finish(uint8_t* out, Writer* w) {
  const auto body_end = static_cast<std::size_t>(w->pos() - out);
  w->U32(Crc32(out + 2, body_end - 2));
  return body_end + kCrcSize;
}

void WriteHeader(Writer* w, FrameType type, std::size_t payload, uint32_t seq) {
  w->U8(kSync0);
  w->U8(kSync1);
  w->U8(kProtocolVersion);
  w->U8(static_cast<uint8_t>(type));
  w->U16(static_cast<uint16_t>(payload));
  w->U32(seq);
}

}  // namespace

std::size_t EncodeSensorFrame(const SensorFrame& f, uint8_t* out) {
  Writer w(out);
  WriteHeader(&w, FrameType::kSensor, kSensorPayloadSize, f.seq);
  w.U64(f.device_time_us);
  for (uint16_t v : f.adc) w.U16(v);
  for (int16_t v : f.gyro_raw) w.I16(v);
  for (int16_t v : f.accel_raw) w.I16(v);
  w.U16(f.status);
  w.U8(f.leg_fault_mask);
  w.U8(0);  // reserved
  w.U32(f.last_command_seq);
  w.U32(f.command_age_us);
  for (int16_t v : f.applied_drive) w.I16(v);
  w.U32(f.rx_corrupt);
  w.U32(f.rx_lost);
  w.U32(f.command_session);
  w.U32(f.rx_session_rejected);
  return Finish(out, &w);
}

std::size_t EncodeCommandFrame(const CommandFrame& f, uint8_t* out) {
  Writer w(out);
  WriteHeader(&w, FrameType::kCommand, kCommandPayloadSize, f.seq);
  w.U32(f.watchdog_us);
  for (int16_t v : f.drive) w.I16(v);
  w.U16(f.flags);
  w.U16(0);  // reserved
  w.U32(f.session);
  return Finish(out, &w);
}

DecodeStatus DecodeFrame(const uint8_t* data, std::size_t size, DecodedFrame* out,
                         std::size_t* consumed) {
  if (size >= 1 && data[0] != kSync0) return DecodeStatus::kBadSync;
  if (size >= 2 && data[1] != kSync1) return DecodeStatus::kBadSync;
  if (size >= 3 && data[2] != kProtocolVersion) return DecodeStatus::kBadVersion;
  if (size >= 4 && PayloadSize(data[3]) == 0) return DecodeStatus::kBadType;
  if (size < kHeaderSize) return DecodeStatus::kNeedMore;
  Reader header(data + 4);
  const std::size_t payload = header.U16();
  const uint32_t seq = header.U32();
  if (payload != PayloadSize(data[3])) return DecodeStatus::kBadLength;
  const std::size_t total = kHeaderSize + payload + kCrcSize;
  if (size < total) return DecodeStatus::kNeedMore;
  if (Reader(data + kHeaderSize + payload).U32() != Crc32(data + 2, kHeaderSize - 2 + payload)) {
    return DecodeStatus::kBadCrc;
  }
  Reader r(data + kHeaderSize);
  out->type = static_cast<FrameType>(data[3]);
  if (out->type == FrameType::kSensor) {
    SensorFrame& f = out->sensor;
    f.seq = seq;
    f.device_time_us = r.U64();
    for (uint16_t& v : f.adc) v = r.U16();
    for (int16_t& v : f.gyro_raw) v = r.I16();
    for (int16_t& v : f.accel_raw) v = r.I16();
    f.status = r.U16();
    f.leg_fault_mask = r.U8();
    r.U8();
    f.last_command_seq = r.U32();
    f.command_age_us = r.U32();
    for (int16_t& v : f.applied_drive) v = r.I16();
    f.rx_corrupt = r.U32();
    f.rx_lost = r.U32();
    f.command_session = r.U32();
    f.rx_session_rejected = r.U32();
  } else {
    CommandFrame& f = out->command;
    f.seq = seq;
    f.watchdog_us = r.U32();
    for (int16_t& v : f.drive) v = r.I16();
    f.flags = r.U16();
    r.U16();  // reserved
    f.session = r.U32();
    const bool drive_ok = std::none_of(f.drive.begin(), f.drive.end(),
                                       [](int16_t d) { return d < -kDriveFullScale; });
    if (!drive_ok || f.watchdog_us < kMinWatchdogUs || f.watchdog_us > kMaxWatchdogUs ||
        f.session == 0) {
      return DecodeStatus::kBadField;
    }
  }
  *consumed = total;
  return DecodeStatus::kOk;
}

bool AsksForNoMotion(const CommandFrame& frame) {
  return (frame.flags & kCommandEnable) == 0 ||
         std::all_of(frame.drive.begin(), frame.drive.end(), [](int16_t d) { return d == 0; });
}

DecodeStatus DecodeDatagram(const uint8_t* data, std::size_t size, DecodedFrame* out) {
  std::size_t consumed = 0;
  const DecodeStatus status = DecodeFrame(data, size, out, &consumed);
  if (status == DecodeStatus::kOk && consumed != size) return DecodeStatus::kBadLength;
  return status;
}

void RxStats::Count(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk:
      ++frames_ok;
      break;
    case DecodeStatus::kBadCrc:
      ++bad_crc;
      break;
    case DecodeStatus::kNeedMore:
    case DecodeStatus::kBadLength:
      ++bad_length;
      break;
    case DecodeStatus::kBadSync:
    case DecodeStatus::kBadVersion:
    case DecodeStatus::kBadType:
      ++bad_header;
      break;
    case DecodeStatus::kBadField:
      ++bad_field;
      break;
  }
}

void StreamParser::Drop(std::size_t n) {
  std::memmove(buffer_.data(), buffer_.data() + n, size_ - n);
  size_ -= n;
}

bool StreamParser::Extract(DecodedFrame* frame, DecodeStatus* status) {
  for (;;) {
    // Skip to the next candidate sync; garbage between frames (or a lone
    // 0xA5 in it) is not a frame error, only skipped bytes.
    std::size_t start = 0;
    while (start < size_ && buffer_[start] != kSync0) ++start;
    if (start > 0) {
      stats_.bytes_skipped += start;
      Drop(start);
    }
    if (size_ == 0) return false;
    std::size_t consumed = 0;
    *status = DecodeFrame(buffer_.data(), size_, frame, &consumed);
    if (*status == DecodeStatus::kNeedMore) return false;
    if (*status == DecodeStatus::kBadSync) {
      ++stats_.bytes_skipped;
      Drop(1);
      continue;
    }
    stats_.Count(*status);
    // On an error resync one byte further: the real frame may start inside.
    Drop(*status == DecodeStatus::kOk ? consumed : 1);
    return true;
  }
}

}  // namespace stewart::hw
