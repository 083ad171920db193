#pragma once
// An LCM log file (the format lcm-logger and stewart_logger write), indexed
// once at open by *stack time*: for each channel, every event's utime (the
// first field of every stewart message, after lcm-gen's 8-byte fingerprint)
// and its payload's offset in the file. Seeking to any instant is then a
// binary search per channel and one read per message, whatever the log's
// length. Raw bytes only: decoding is the caller's (no LCM dependency).
// Not lcm::LogFile (which the replay and the log export use for sequential
// reading): it exposes no event offsets, and its stream position after an
// event is off at the end of a log cut short (LCM 1.3 reads ahead for the
// next sync word), which would misplace the last payload.
#include <cstdint>
#include <string>
#include <vector>

namespace stewart::viewer {

class LcmLogIndex {
 public:
  struct Event {
    int64_t utime_us;        ///< the message's own utime (stack time)
    int64_t payload_offset;  ///< in the file
    int32_t payload_bytes;
  };

  /// Reads and indexes the log. Throws InputError naming the file when it
  /// cannot be opened or is not an LCM log; a log cut short at its end (a
  /// logger that was killed) keeps its complete events.
  explicit LcmLogIndex(const std::string& path);
  ~LcmLogIndex();
  LcmLogIndex(const LcmLogIndex&) = delete;
  LcmLogIndex& operator=(const LcmLogIndex&) = delete;

  /// Events of `channel`, ordered by utime (empty for a channel not in the log).
  const std::vector<Event>& EventsOf(const std::string& channel) const;
  /// The last event of `channel` with utime <= utime_us, nullptr when none.
  const Event* LatestAtOrBefore(const std::string& channel, int64_t utime_us) const;
  /// The payload of an event (throws std::runtime_error when the read fails).
  std::vector<uint8_t> Payload(const Event& event) const;

  const std::string& path() const { return path_; }
  int64_t total_events() const { return total_events_; }
  bool truncated() const { return truncated_; }

 private:
  std::string path_;
  int fd_ = -1;
  std::vector<std::string> channel_names_;
  std::vector<std::vector<Event>> events_;  ///< per channel, index as channel_names_
  int64_t total_events_ = 0;
  bool truncated_ = false;
};

}  // namespace stewart::viewer
