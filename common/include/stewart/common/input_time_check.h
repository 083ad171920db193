#pragma once
// The time checks a process makes on its inputs, with their bookkeeping:
// TimePlausibility on the stream that carries its stack time (the time
// source: sensor samples for the estimator, state estimates for the
// controller and the safety process), the same mapping for its other inputs
// (checked, never moving it), rejections counted into its HealthCounters
// under one name per input ("rejected_<input>_time_implausible") and
// InputStarvation on the time source, which makes the process FAULT while
// it rejects every message of it.
//
// The process calls, per message of its time source:
//   CheckSource(...)    false: rejected and counted, drop the message;
//   then either SourceAccepted(...) when it used the message, or
//   SourceRejected(...) when its own rules (time order) dropped it whole.
// Per message of another input: CheckOther(...).
//
// LCM-free; a receive time is optional (nullopt in replay and in process),
// see time_plausibility.h for what it changes.
#include <cstdint>
#include <optional>
#include <string>

#include "stewart/common/health_counters.h"
#include "stewart/common/input_starvation.h"
#include "stewart/common/time_plausibility.h"

namespace stewart {

class InputTimeCheck {
 public:
  /// `source` names the time source in counters and errors ("state",
  /// "sensor"); `stale_age_s` is the process's own stale age (starvation);
  /// `counters` must outlive this object.
  InputTimeCheck(const TimePlausibilityParams& params, std::string source, double stale_age_s,
                 HealthCounters* counters);

  /// A message of the time source: its utime and sample_utime checked.
  bool CheckSource(int64_t utime, int64_t sample_utime, std::optional<int64_t> receive_wall_us);
  /// The process used it: its utime may become the newest time. Ends a
  /// starvation (the state returns to OK; the FAULT stays latched).
  void SourceAccepted(int64_t utime, std::optional<int64_t> receive_wall_us);
  /// The process dropped it whole by its own rules (already counted there).
  /// A copy of the newest accepted message does not count towards starvation.
  void SourceRejected(int64_t utime, std::optional<int64_t> receive_wall_us);

  /// A message of another input (`input` names its counter, e.g. "nominal"),
  /// checked against the time source's mapping, which it never moves. False:
  /// rejected and counted.
  bool CheckOther(const char* input, int64_t utime, int64_t sample_utime,
                  std::optional<int64_t> receive_wall_us);

  const TimePlausibility& plausibility() const { return plausibility_; }
  bool starved() const { return starvation_.starved(); }

 private:
  /// The first implausible of the two times, or kPlausible.
  TimeVerdict Verdict(int64_t utime, int64_t sample_utime, std::optional<int64_t> receive_wall_us,
                      int64_t* offending_utime) const;
  void Reject(const std::string& reason, TimeVerdict verdict, int64_t offending_utime);
  void NoteSourceRejection(int64_t utime, std::optional<int64_t> receive_wall_us);

  TimePlausibility plausibility_;
  InputStarvation starvation_;
  std::string source_;
  std::string source_reason_;  ///< "<source>_time_implausible", made once
  double window_s_;
  HealthCounters* counters_;
};

}  // namespace stewart
