#include "continuity_report.h"

#include <spdlog/fmt/fmt.h>

namespace stewart {
namespace {

double Percent(long part, long whole) {
  return whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

double SinceStartS(int64_t log_utime, const LogSpan& span) {
  return 1e-6 * static_cast<double>(log_utime - span.first_log_utime);
}

}  // namespace

std::string FormatContinuity(const SeqContinuity& c, const LogSpan& span) {
  const long published = c.recorded() + c.missing();
  std::string o;
  if (c.missing() == 0 && c.restarts() == 0) {
    return fmt::format("log: complete: {} numbered messages in {} streams, no gap in any seq\n",
                       c.recorded(), c.streams().size());
  }
  if (c.missing() > 0) {
    long gaps = 0;
    for (const auto& [name, s] : c.streams()) gaps += s.gaps;
    o += fmt::format(
        "log: WARNING: {} of {} published messages are missing from the log ({:.1f} %, in {} "
        "gaps)",
        c.missing(), published, Percent(c.missing(), published), gaps);
  } else {
    o += fmt::format("log: no message missing ({} recorded)", c.recorded());
  }
  if (c.restarts() > 0) {
    o += fmt::format("; WARNING: {} publisher restart(s) (seq fell back)", c.restarts());
  }
  o += "\n";
  for (const auto& [name, s] : c.streams()) {
    if (s.missing == 0 && s.restarts == 0) continue;
    o += fmt::format("  {}: {} recorded", name, s.recorded);
    if (s.missing > 0) {
      o += fmt::format(", {} missing ({:.1f} %) in {} gap(s)", s.missing,
                       Percent(s.missing, s.recorded + s.missing), s.gaps);
    }
    if (s.restarts > 0) o += fmt::format(", restarted {} time(s)", s.restarts);
    // Where it started to go wrong.
    for (const SeqEvent& e : c.events()) {
      if (e.stream != name) continue;
      o += fmt::format("; first {} at utime {} us (log +{:.3f} s, seq {} -> {})", ToString(e.kind),
                       e.utime, SinceStartS(e.log_utime, span), e.previous_seq, e.seq);
      break;
    }
    o += "\n";
  }
  return o;
}

nlohmann::ordered_json ContinuityJson(const SeqContinuity& c, const LogSpan& span,
                                      size_t max_events) {
  nlohmann::ordered_json j;
  j["recorded"] = c.recorded();
  j["missing"] = c.missing();
  j["restarts"] = c.restarts();
  j["log_first_utime_us"] = span.first_log_utime;
  j["log_last_utime_us"] = span.last_log_utime;
  nlohmann::ordered_json streams = nlohmann::ordered_json::object();
  for (const auto& [name, s] : c.streams()) {
    streams[name] = {{"recorded", s.recorded},
                     {"missing", s.missing},
                     {"gaps", s.gaps},
                     {"restarts", s.restarts},
                     {"first_utime_us", s.first_utime},
                     {"last_utime_us", s.last_utime},
                     {"first_log_utime_us", s.first_log_utime},
                     {"last_log_utime_us", s.last_log_utime},
                     {"last_seq", s.last_seq}};
  }
  j["streams"] = streams;
  nlohmann::ordered_json events = nlohmann::ordered_json::array();
  for (size_t i = 0; i < c.events().size() && i < max_events; ++i) {
    const SeqEvent& e = c.events()[i];
    events.push_back({{"kind", ToString(e.kind)},
                      {"stream", e.stream},
                      {"seq", e.seq},
                      {"previous_seq", e.previous_seq},
                      {"utime_us", e.utime},
                      {"previous_utime_us", e.previous_utime},
                      {"log_utime_us", e.log_utime},
                      {"missing", e.missing}});
  }
  j["events"] = events;
  j["events_left_off"] = c.events().size() > max_events ? c.events().size() - max_events : 0;
  return j;
}

}  // namespace stewart
