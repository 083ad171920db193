#pragma once
// Answering an input again that was answered already: the lockstep plant's
// resend (docs/simulation.md, "Lockstep mode"). plant_sim publishes a sample
// and waits for the safe command answering it; after 0.2 s without one it
// sends the same sample again, byte for byte. If a message of the loop was
// lost downstream (UDP drops silently, e.g. when a receive queue overflows),
// every node before the loss has answered already and would drop the resent
// input as out of order: nothing moves and the loop stalls until the
// plant's lockstep timeout.
//
// The rule: a node that receives again the exact input it last answered
// (same utime and seq) answers again with the output it sent for it, without
// running its update again (the state is not advanced twice, and the answer
// is the same bytes, so a receiver that had it drops the copy as any
// duplicate). Only the input last answered: an older one was answered and
// followed by newer ones, so nothing waits on it.
//
// Rate: on a live bus (a receive time given) an input is answered again at
// most once per `min_interval_us` of receive time since its previous answer
// (kResendMinIntervalUs, 0.1 s: half of plant_sim's resend period, so every
// resend of a stalled lockstep loop is answered, while in real time, where
// the newest input changes every period, a copy of it arriving within 0.1 s
// of its answer is handled as before: rejected as a duplicate, counted). A
// flood of copies therefore costs at most 10 answers a second per node, not
// one per copy. Without a receive time (replay, the in-process loop: no bus
// to flood) every resend is answered again; the answer is the same output,
// so a replay pairs it with the same recorded message either way.
//
// LCM-free; the process keeps its last output, this class decides.
#include <cstdint>
#include <optional>

namespace stewart {

/// Half of plant_sim's lockstep resend period (LockstepPacing::kStallResend).
inline constexpr int64_t kResendMinIntervalUs = 100'000;

class ResendAnswer {
 public:
  explicit ResendAnswer(int64_t min_interval_us = kResendMinIntervalUs)
      : min_interval_us_(min_interval_us) {}

  /// The process answered the input (`utime`, `seq`) with an output it keeps.
  void Answered(int64_t utime, int64_t seq, std::optional<int64_t> receive_wall_us);

  /// An input arrived: true when it is the input last answered and may be
  /// answered again now (then its answer time is renewed); false otherwise,
  /// and the process handles it as any input. An input newer than the one
  /// answered (by utime) ends the rule for that one: the loop moved on.
  bool AnswerAgain(int64_t utime, int64_t seq, std::optional<int64_t> receive_wall_us);

  /// Forget the last answer (the process's next output will answer another
  /// input, or it published nothing for the last one).
  void Clear() { answered_ = false; }

 private:
  int64_t min_interval_us_;
  bool answered_ = false;
  int64_t utime_ = 0;
  int64_t seq_ = 0;
  std::optional<int64_t> answered_wall_us_;
};

}  // namespace stewart
