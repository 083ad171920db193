#pragma once
// Which received safe commands act on the plant (docs/simulation.md,
// "Modes"), and why the others are rejected. No LCM: the node converts
// force_command_t and supervisor_state_t, verifies their MACs, and turns a
// rejection into a health counter named by `reason`.
//
// First the trust rules every actuator applies (guard/safe_command_acceptor.h:
// authentic, the announced safety session, seq increasing, sample neither
// ahead of the newest published one nor older than command_timeout_s). Then
// the mode's: lockstep: a command answers the awaited sample iff it carries
// its sample_utime, and only the first answer counts; a command the trust
// rules reject is never the answer. Real time: a command older than the one
// applied is refused; the rest go to RealTimeCommandHold.
#include <cstdint>
#include <string>

#include "stewart/common/signals.h"
#include "stewart/guard/safe_command_acceptor.h"
#include "stewart/model/types.h"

namespace stewart {

class CommandGate {
 public:
  enum class Action {
    kApply,   ///< real time: hand it to RealTimeCommandHold
    kAnswer,  ///< lockstep: the answer to the awaited sample (answer())
    kReject,
  };
  struct Decision {
    Action action = Action::kReject;
    std::string reason;  ///< the rejection's health counter
    std::string detail;
    /// The command passed the trust rules, so it counts for the loop latency
    /// even when the mode refuses it.
    bool timed = false;
  };

  CommandGate(bool lockstep, const SafeCommandAcceptorLimits& limits);

  /// The plant published its sample `sample_utime`: in lockstep the one now
  /// awaited; in both the newest, that every age is measured against.
  void OnSamplePublished(int64_t sample_utime);

  /// A session announcement (supervisor_state_t); `authentic`: its MAC
  /// verified; `wall_us`: the plant's monotonic clock.
  AnnouncementVerdict OnAnnouncement(const SessionAnnouncement& a, bool authentic,
                                     int64_t wall_us) {
    return acceptor_.OnAnnouncement(a, authentic, wall_us);
  }

  /// A safe command; `authentic`: its MAC verified (true without a key).
  Decision Check(const ForceCommand& command, bool authentic);

  bool answered() const { return answered_; }
  /// Lockstep: the answer to the awaited sample, once answered().
  const ForceCommand& answer() const { return answer_; }
  /// The sample the newest applied command answered; -1 before the first.
  int64_t last_applied_sample_utime() const { return last_applied_sample_utime_; }
  const SafeCommandAcceptor& acceptor() const { return acceptor_; }

 private:
  bool lockstep_;
  SafeCommandAcceptor acceptor_;
  int64_t newest_sample_utime_ = 0;
  bool answered_ = false;
  ForceCommand answer_;
  int64_t last_applied_sample_utime_ = -1;
};

}  // namespace stewart
