#include "stewart/hw_emulator/command_session_check.h"

#include <algorithm>

namespace stewart::hw {

bool IsSessionRejection(CommandAcceptance a) {
  return a == CommandAcceptance::kRetiredSession || a == CommandAcceptance::kSessionLive ||
         a == CommandAcceptance::kNeedsNoMotion;
}

bool CommandSessionCheck::Retired(uint32_t session) const {
  return std::find(retired_.begin(), retired_.end(), session) != retired_.end();
}

CommandAcceptance CommandSessionCheck::Accept(const CommandFrame& frame, bool current_drives) {
  if (session_ != 0 && frame.session == session_) {
    // Signed difference: a wrapping uint32 seq still orders correctly.
    const auto gap = static_cast<int32_t>(frame.seq - last_seq_);
    if (gap <= 0) return CommandAcceptance::kNotNewer;
    rx_lost_ += static_cast<uint32_t>(gap - 1);
    last_seq_ = frame.seq;
    return CommandAcceptance::kApplied;
  }
  // Another session. Its seq says nothing against the current one's: a
  // restarted bridge counts from its start again.
  CommandAcceptance verdict = CommandAcceptance::kAdopted;
  if (frame.session == 0 || Retired(frame.session)) {
    // An old bridge's frame, late: never again, whatever its seq. (0 never
    // comes off the wire, the decoder rejects it as bad_field.)
    verdict = CommandAcceptance::kRetiredSession;
  } else if (session_ != 0 && current_drives) {
    // A second host while the first still drives: the first keeps the legs.
    verdict = CommandAcceptance::kSessionLive;
  } else if (!AsksForNoMotion(frame)) {
    // A session starts at rest: the host sends zero drive until it sees
    // its session echoed, so a motion frame here is not a conforming start.
    verdict = CommandAcceptance::kNeedsNoMotion;
  }
  if (verdict != CommandAcceptance::kAdopted) {
    ++rx_session_rejected_;
    return verdict;
  }
  if (session_ != 0) {
    retired_[next_retired_] = session_;
    next_retired_ = (next_retired_ + 1) % kRetiredSessions;
  }
  session_ = frame.session;
  last_seq_ = frame.seq;
  ++sessions_adopted_;
  return CommandAcceptance::kAdopted;
}

}  // namespace stewart::hw
