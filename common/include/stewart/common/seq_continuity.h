#pragma once
// Whether a recorded stream of numbered messages is complete. Every
// publisher of the stack numbers its messages (`seq`: 0 at its start, +1 per
// message), so a log shows what it lacks (a gap: published, not recorded)
// and where a publisher restarted (its seq falls back). The recording check
// (stewart_log_export --check, run by tools/launch.sh), the report and
// stewart_replay share this one reading of it. docs/operations.md, "Logging".
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace stewart {

enum class SeqEventKind {
  kGap,      ///< seq jumped forward: the log lacks the messages in between
  kRestart,  ///< seq fell back (or repeated with another utime): the publisher started again
};

const char* ToString(SeqEventKind kind);

/// One discontinuity of a stream, at the first message after it.
struct SeqEvent {
  SeqEventKind kind = SeqEventKind::kGap;
  std::string stream;
  int64_t seq = 0;            ///< of the first message after the event
  int64_t previous_seq = -1;  ///< of the stream's message before it; -1: none (log start)
  int64_t utime = 0;          ///< stack time of the first message after it (us)
  int64_t previous_utime = -1;
  int64_t log_utime = 0;  ///< the logger's receive time of that message (us)
  /// Messages the log lacks here: a gap's skipped seqs; after a restart, the
  /// restarted publisher's first messages (its first recorded seq).
  long missing = 0;
  long position = 0;  ///< the caller's index of the message (e.g. its event in the log)
};

struct SeqStreamStats {
  long recorded = 0;
  long missing = 0;
  long gaps = 0;  ///< bursts of missing messages (a restart whose first seqs are missing too)
  long restarts = 0;
  /// Copies of the message before (same seq and utime): a lockstep resend
  /// and its answers (common/resend_answer.h), not a restart.
  long repeats = 0;
  int64_t first_utime = -1;
  int64_t last_utime = -1;
  int64_t first_log_utime = -1;
  int64_t last_log_utime = -1;
  int64_t last_seq = -1;
};

/// Streams by name (a channel, or channel[publisher] where publishers share
/// it). Observe every message in log order.
class SeqContinuity {
 public:
  /// One recorded message of `stream`: the discontinuity it reveals, if any
  /// (also kept in events()).
  std::optional<SeqEvent> Observe(const std::string& stream, int64_t seq, int64_t utime,
                                  int64_t log_utime, long position);

  const std::map<std::string, SeqStreamStats>& streams() const { return streams_; }
  const std::vector<SeqEvent>& events() const { return events_; }  ///< in log order
  long recorded() const;
  long missing() const;
  long restarts() const;
  /// The first restart of any stream, if any.
  const SeqEvent* first_restart() const;

 private:
  std::map<std::string, SeqStreamStats> streams_;
  std::vector<SeqEvent> events_;
};

}  // namespace stewart
