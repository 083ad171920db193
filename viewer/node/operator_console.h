#pragma once
// The page's operator buttons (only with --operator): each becomes an
// operator_command_t signed with the run's key and published on the
// operator channel, as stewart_ctl does. The supervisor decides; its answer
// comes back on the supervisor channel and shows in the page.
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/node/message_auth.h"

namespace stewart::viewer {

class OperatorConsole {
 public:
  OperatorConsole(const StackConfig& config, lcm::LCM* lcm);
  /// verb: arm, hold, resume, estop or reset (already validated).
  void Send(const std::string& verb, const std::string& note);
  int64_t operator_id() const { return operator_id_; }

 private:
  std::mutex mutex_;  ///< browsers press buttons on civetweb's threads
  MessageAuthenticator auth_;
  lcm::LCM* lcm_;
  std::string channel_;
  int64_t operator_id_;
  int64_t seq_ = 0;
};

}  // namespace stewart::viewer
