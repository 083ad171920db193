#include "stewart/plant_sim/lockstep_pacing.h"

#include <algorithm>

namespace stewart {
namespace {

LockstepPacing::Clock::duration FromSeconds(double s) {
  return std::chrono::duration_cast<LockstepPacing::Clock::duration>(
      std::chrono::duration<double>(s));
}

}  // namespace

LockstepPacing::LockstepPacing(double timeout_s, double startup_republish_s)
    : timeout_(FromSeconds(timeout_s)),
      startup_republish_(FromSeconds(startup_republish_s)),
      startup_republish_enabled_(startup_republish_s > 0.0) {}

void LockstepPacing::StartWaiting(int64_t tick, Clock::time_point now) {
  tick_ = tick;
  waiting_since_ = now;
  last_sent_ = now;
}

LockstepPacing::Step LockstepPacing::Poll(Clock::time_point now) {
  Step step;
  if (now - waiting_since_ >= timeout_) {
    step.timed_out = true;
    return step;
  }
  const Clock::duration resend_every = tick_ == 0 ? startup_republish_ : kStallResend;
  const bool resend_enabled = tick_ > 0 || startup_republish_enabled_;
  if (resend_enabled && now - last_sent_ >= resend_every) {
    step.resend = true;
    last_sent_ = now;
  }
  const Clock::duration remaining = timeout_ - (now - waiting_since_);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::min<Clock::duration>(remaining, resend_every))
                      .count();
  step.wait_ms = static_cast<int>(std::max<int64_t>(0, std::min<int64_t>(ms, kMaxWaitMs)));
  return step;
}

}  // namespace stewart
