#pragma once
// The operator console's view of the supervisor (stewart_ctl, the viewer's
// operator buttons' tests): the supervisor's states on its channel, each
// verified under the bus key, and a wait for the one state that answers a
// given command.
//
// Every state a receive call drains is judged, not only the newest: the
// safety process announces a new state for every operator message, so a
// dead-man console's heartbeat that lands right after a command's answer
// would otherwise hide the answer (its state names the heartbeat's operator).
#include <cstdint>
#include <functional>
#include <string>

#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {

class SupervisorListener {
 public:
  /// Subscribes to `channel` on `url`; `auth` (not owned, outlives this)
  /// verifies each state, and those that fail are dropped and counted.
  SupervisorListener(const std::string& url, const std::string& channel,
                     MessageAuthenticator* auth);

  /// Receives until a verified state for which `accept` holds arrives, or
  /// `timeout_s` passes, or `stop` returns true. True, with that state in
  /// matched(), when one did. States already received by an earlier wait
  /// are not judged again.
  bool WaitFor(
      double timeout_s, const std::function<bool(const supervisor_state_t&)>& accept,
      const std::function<bool()>& stop = [] { return false; });

  /// The state that ended the last successful WaitFor.
  const supervisor_state_t& matched() const { return matched_; }
  /// The newest verified state received (any, matched or not).
  const supervisor_state_t& latest() const { return latest_; }
  int64_t received() const { return received_; }
  int64_t forged() const { return forged_; }

  void On(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
          const supervisor_state_t* msg);

 private:
  LcmReceiver receiver_;
  MessageAuthenticator* auth_;
  const std::function<bool(const supervisor_state_t&)>* accept_ = nullptr;
  supervisor_state_t latest_{};
  supervisor_state_t matched_{};
  bool has_match_ = false;
  int64_t received_ = 0;
  int64_t forged_ = 0;
};

}  // namespace stewart
