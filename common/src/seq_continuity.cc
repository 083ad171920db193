#include "stewart/common/seq_continuity.h"

namespace stewart {

const char* ToString(SeqEventKind kind) { return kind == SeqEventKind::kGap ? "gap" : "restart"; }

std::optional<SeqEvent> SeqContinuity::Observe(const std::string& stream, int64_t seq,
                                               int64_t utime, int64_t log_utime, long position) {
  SeqStreamStats& s = streams_[stream];
  const bool first = s.recorded == 0;
  std::optional<SeqEvent> event;
  if (!first && seq == s.last_seq && utime == s.last_utime) {
    // The same message again (a resend): the publisher did not restart.
    ++s.recorded;
    ++s.repeats;
    s.last_log_utime = log_utime;
    return event;
  }
  // A publisher starts at seq 0: a first recorded seq > 0 means the log
  // lacks the stream's first messages.
  const int64_t expected = first ? 0 : s.last_seq + 1;
  if (seq != expected) {
    SeqEvent e;
    e.stream = stream;
    e.seq = seq;
    e.previous_seq = first ? -1 : s.last_seq;
    e.utime = utime;
    e.previous_utime = first ? -1 : s.last_utime;
    e.log_utime = log_utime;
    e.position = position;
    if (seq > expected) {
      e.kind = SeqEventKind::kGap;
      e.missing = static_cast<long>(seq - expected);
    } else {
      // Fell back (or repeated at another time): a new publisher under the same name. Its
      // messages before the first recorded one are missing too.
      e.kind = SeqEventKind::kRestart;
      e.missing = seq > 0 ? static_cast<long>(seq) : 0;
      ++s.restarts;
    }
    if (e.missing > 0) {
      s.missing += e.missing;
      ++s.gaps;
    }
    events_.push_back(e);
    event = e;
  }
  ++s.recorded;
  s.last_seq = seq;
  s.last_utime = utime;
  s.last_log_utime = log_utime;
  if (first) {
    s.first_utime = utime;
    s.first_log_utime = log_utime;
  }
  return event;
}

long SeqContinuity::recorded() const {
  long n = 0;
  for (const auto& [name, s] : streams_) n += s.recorded;
  return n;
}

long SeqContinuity::missing() const {
  long n = 0;
  for (const auto& [name, s] : streams_) n += s.missing;
  return n;
}

long SeqContinuity::restarts() const {
  long n = 0;
  for (const auto& [name, s] : streams_) n += s.restarts;
  return n;
}

const SeqEvent* SeqContinuity::first_restart() const {
  for (const SeqEvent& e : events_) {
    if (e.kind == SeqEventKind::kRestart) return &e;
  }
  return nullptr;
}

}  // namespace stewart
