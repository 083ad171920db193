#pragma once
// Whether a receiver has rejected every message of its input stream for
// longer than its stale age: it then acts on nothing, although messages
// arrive, and must say so in its health (FAULT) instead of looking idle.
//
// "Longer than" is measured on the receive path's wall clock when the
// messages have receive times (a live process). Without them (replay, the
// in-process loop) it is measured on the rejected messages' own stack times,
// over a run of rejected messages each within the window of the previous
// one, so a single message with a far-off time never makes a receiver
// starved. Starvation ends at the next accepted message.
//
// LCM-free and allocation-free.
#include <cstdint>
#include <optional>

namespace stewart {

class InputStarvation {
 public:
  /// `stale_age_s` > 0: the receiver's own stale age; `window_s` > 0: the
  /// time plausibility window (TimePlausibilityParams::window_s).
  InputStarvation(double stale_age_s, double window_s);

  /// A message was accepted. Returns true when this ended a starvation.
  bool OnAccepted();
  /// A message was rejected (whole: nothing of it was used). Returns
  /// starved() after it.
  bool OnRejected(int64_t utime, std::optional<int64_t> receive_wall_us);

  bool starved() const { return starved_; }
  int64_t stale_age_us() const { return stale_age_us_; }

 private:
  int64_t stale_age_us_;
  int64_t window_us_;
  bool starved_ = false;
  bool rejecting_ = false;  ///< every message since the last accepted one was rejected
  /// Receive time of the first rejection since the last accepted message:
  /// rejections count from there (not from the last acceptance, so one
  /// rejected message after a silence is not a starvation).
  std::optional<int64_t> since_wall_us_;
  /// The current run of consistent rejected stack times (no receive times).
  int64_t run_first_utime_ = 0;
  int64_t run_last_utime_ = 0;
};

}  // namespace stewart
