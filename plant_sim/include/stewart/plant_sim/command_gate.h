#pragma once
// Which received force commands act on the plant (docs/simulation.md,
// "Modes"), and why the others are rejected. No LCM: the node converts
// force_command_t and turns a rejection into a health counter named by
// `reason`.
//
// Lockstep: a command answers the awaited sample iff it carries its
// sample_utime, and only the first answer counts. Real time: a command for a
// sample not yet published, or older than the one applied, is refused; the
// rest go to RealTimeCommandHold.
#include <cstdint>
#include <string>

#include "stewart/model/types.h"

namespace stewart {

class CommandGate {
 public:
  enum class Action {
    kApply,   ///< real time: hand it to RealTimeCommandHold
    kAnswer,  ///< lockstep: the answer to the awaited sample (answer_force_n())
    kReject,
  };
  struct Decision {
    Action action = Action::kReject;
    std::string reason;  ///< the rejection's health counter
    std::string detail;
    /// The command carries a usable force, so it counts for the loop latency
    /// even when the gate refuses it.
    bool timed = false;
  };

  explicit CommandGate(bool lockstep) : lockstep_(lockstep) {}

  /// The plant published its sample `sample_utime`: in lockstep the one now awaited.
  void OnSamplePublished(int64_t sample_utime);

  Decision Check(const Vector6d& force_n, int64_t sample_utime, int64_t seq);

  bool answered() const { return answered_; }
  const Vector6d& answer_force_n() const { return answer_force_n_; }
  /// The sample the newest applied command answered; -1 before the first.
  int64_t last_applied_sample_utime() const { return last_applied_sample_utime_; }

 private:
  bool lockstep_;
  int64_t newest_sample_utime_ = 0;
  bool answered_ = false;
  Vector6d answer_force_n_ = Vector6d::Zero();
  int64_t last_applied_sample_utime_ = -1;
};

}  // namespace stewart
