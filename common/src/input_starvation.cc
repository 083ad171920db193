#include "stewart/common/input_starvation.h"

#include <cmath>

#include "stewart/common/check.h"

namespace stewart {

InputStarvation::InputStarvation(double stale_age_s, double window_s)
    : stale_age_us_(std::llround(stale_age_s * 1e6)), window_us_(std::llround(window_s * 1e6)) {
  STEWART_CHECK(stale_age_s > 0.0 && std::isfinite(stale_age_s), "stale age must be positive");
  STEWART_CHECK(window_s > 0.0 && std::isfinite(window_s), "the time window must be positive");
}

bool InputStarvation::OnAccepted() {
  const bool ended = starved_;
  starved_ = false;
  rejecting_ = false;
  return ended;
}

bool InputStarvation::OnRejected(int64_t utime, std::optional<int64_t> receive_wall_us) {
  if (!rejecting_) {
    rejecting_ = true;
    since_wall_us_ = receive_wall_us;
    run_first_utime_ = run_last_utime_ = utime;
  } else if (utime > run_last_utime_ && utime - run_last_utime_ <= window_us_) {
    run_last_utime_ = utime;  // the same stream, moving on
  } else if (utime != run_last_utime_) {
    run_first_utime_ = run_last_utime_ = utime;  // another stream (or a far-off message)
  }
  if (receive_wall_us && since_wall_us_) {
    if (*receive_wall_us - *since_wall_us_ > stale_age_us_) starved_ = true;
  } else if (run_last_utime_ - run_first_utime_ > stale_age_us_) {
    starved_ = true;
  }
  return starved_;
}

}  // namespace stewart
