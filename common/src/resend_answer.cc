#include "stewart/common/resend_answer.h"

namespace stewart {

void ResendAnswer::Answered(int64_t utime, int64_t seq, std::optional<int64_t> receive_wall_us) {
  answered_ = true;
  utime_ = utime;
  seq_ = seq;
  answered_wall_us_ = receive_wall_us;
}

bool ResendAnswer::AnswerAgain(int64_t utime, int64_t seq, std::optional<int64_t> receive_wall_us) {
  if (!answered_) return false;
  // A newer input, answered or not, means the loop moved on past the answer.
  if (utime > utime_) answered_ = false;
  if (!answered_ || utime != utime_ || seq != seq_) return false;
  // Live, the interval bounds what a flood of copies can draw out; either
  // time unknown (replay, in process) leaves nothing to flood.
  if (receive_wall_us && answered_wall_us_ &&
      *receive_wall_us - *answered_wall_us_ < min_interval_us_) {
    return false;
  }
  answered_wall_us_ = receive_wall_us;
  return true;
}

}  // namespace stewart
