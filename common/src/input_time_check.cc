#include "stewart/common/input_time_check.h"

#include <cstdio>
#include <utility>

#include "stewart/common/check.h"

namespace stewart {

InputTimeCheck::InputTimeCheck(const TimePlausibilityParams& params, std::string source,
                               double stale_age_s, HealthCounters* counters)
    : plausibility_(params),
      starvation_(stale_age_s, params.window_s),
      source_(std::move(source)),
      source_reason_(source_ + "_time_implausible"),
      window_s_(params.window_s),
      counters_(counters) {
  STEWART_CHECK(counters_ != nullptr, "InputTimeCheck needs its counters");
}

TimeVerdict InputTimeCheck::Verdict(int64_t utime, int64_t sample_utime,
                                    std::optional<int64_t> receive_wall_us,
                                    int64_t* offending_utime) const {
  *offending_utime = utime;
  TimeVerdict verdict = plausibility_.Check(utime, receive_wall_us);
  if (verdict != TimeVerdict::kPlausible || sample_utime == utime) return verdict;
  *offending_utime = sample_utime;
  return plausibility_.Check(sample_utime, receive_wall_us);
}

void InputTimeCheck::Reject(const std::string& reason, TimeVerdict verdict,
                            int64_t offending_utime) {
  // Only on a rejection, so the formatting costs nothing in the loop.
  char detail[200];
  std::snprintf(detail, sizeof detail,
                "utime %lld us is %s (newest accepted %lld us, lcm.time_window_s %g)",
                static_cast<long long>(offending_utime), ToString(verdict),
                static_cast<long long>(plausibility_.newest_utime()), window_s_);
  counters_->Reject(reason, detail);
}

bool InputTimeCheck::CheckSource(int64_t utime, int64_t sample_utime,
                                 std::optional<int64_t> receive_wall_us) {
  int64_t offending = 0;
  const TimeVerdict verdict = Verdict(utime, sample_utime, receive_wall_us, &offending);
  if (verdict == TimeVerdict::kPlausible) return true;
  Reject(source_reason_, verdict, offending);
  NoteSourceRejection(utime, receive_wall_us);
  return false;
}

void InputTimeCheck::SourceAccepted(int64_t utime, std::optional<int64_t> receive_wall_us) {
  plausibility_.Accept(utime, receive_wall_us);
  if (starvation_.OnAccepted()) counters_->SetState(health_state::kOk);
}

void InputTimeCheck::SourceRejected(int64_t utime, std::optional<int64_t> receive_wall_us) {
  // A copy of the newest message (lockstep re-sends a sample the stack has
  // not answered yet) is not a sign of a stream this process cannot follow.
  if (plausibility_.anchored() && utime == plausibility_.newest_utime()) return;
  NoteSourceRejection(utime, receive_wall_us);
}

void InputTimeCheck::NoteSourceRejection(int64_t utime, std::optional<int64_t> receive_wall_us) {
  if (!starvation_.OnRejected(utime, receive_wall_us)) return;
  if (counters_->state() != health_state::kFault) {
    counters_->SetError("every " + source_ + " rejected for longer than the stale age (" +
                        std::to_string(1e-6 * static_cast<double>(starvation_.stale_age_us())) +
                        " s), last: " + counters_->last_error());
  }
  counters_->SetState(health_state::kFault);
}

bool InputTimeCheck::CheckOther(const char* input, int64_t utime, int64_t sample_utime,
                                std::optional<int64_t> receive_wall_us) {
  int64_t offending = 0;
  const TimeVerdict verdict = Verdict(utime, sample_utime, receive_wall_us, &offending);
  if (verdict == TimeVerdict::kPlausible) return true;
  Reject(std::string(input) + "_time_implausible", verdict, offending);
  return false;
}

}  // namespace stewart
