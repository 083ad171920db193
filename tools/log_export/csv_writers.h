#pragma once
// One CSV row format per message type; the header names every column with
// its unit, as in docs/messages.md.
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace stewart {

/// What numbers a message in its stream (SeqContinuity): its seq, its stack
/// time and, on a channel several processes share, its publisher.
struct MessageStamp {
  int64_t seq = 0;
  int64_t utime = 0;
  std::string publisher;  ///< "" where one process publishes the channel
};

/// Decodes one LCM payload of a known stewart type and writes it as CSV.
class CsvChannelWriter {
 public:
  virtual ~CsvChannelWriter() = default;
  virtual std::string Header() const = 0;
  /// Returns false if the payload does not decode as this type.
  virtual bool WriteRow(const void* data, int size, std::ostream& out) const = 0;
  /// The payload's stamp; nullopt when it does not decode, or when its seq
  /// does not number one publisher's messages one by one.
  virtual std::optional<MessageStamp> Stamp(const void* data, int size) const = 0;
  /// A small side table from a channel's first message, written as
  /// <channel>.<SidecarName()>.csv; "" when the type has none.
  virtual std::string SidecarName() const { return ""; }
  virtual std::string Sidecar(const void* /*data*/, int /*size*/) const { return ""; }
};

/// The writer for a payload, chosen by the type hash in its first 8 bytes;
/// nullptr for a type this project does not define.
const CsvChannelWriter* FindCsvWriter(const void* data, int size);

}  // namespace stewart
