#pragma once
// How complete a recorded log is, from the seq numbers of its streams
// (stewart/common/seq_continuity.h): a summary for people (the launcher
// prints it after every recorded run) and JSON for the report.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "stewart/common/seq_continuity.h"

namespace stewart {

/// The log's receive-time span, for the events' times relative to its start.
struct LogSpan {
  int64_t first_log_utime = 0;
  int64_t last_log_utime = 0;
};

/// One line for the whole log ("complete" or a WARNING with the counts),
/// then one line per stream with missing messages or restarts.
std::string FormatContinuity(const SeqContinuity& continuity, const LogSpan& span);

/// Counts per stream and the events (the first `max_events`; `events_left_off`
/// says how many more).
nlohmann::ordered_json ContinuityJson(const SeqContinuity& continuity, const LogSpan& span,
                                      size_t max_events = 1000);

}  // namespace stewart
