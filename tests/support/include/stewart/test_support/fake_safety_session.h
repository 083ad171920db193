#pragma once
// A test standing in for the safety process on CMD_SAFE: the actuators
// (plant_sim, hw_bridge) follow only an announced safety session
// (docs/operations.md, "Trust model"), so a test that commands them
// announces one on SUPERVISOR first, as the safety process does, renews it
// every 100 ms of sample time, numbers its commands and signs them when a key
// is given. Header-only; link stewart_node.
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <utility>

#include "stewart/force_command_t.hpp"
#include "stewart/node/message_auth.h"
#include "stewart/supervisor_state_t.hpp"

namespace stewart::test {

class FakeSafetySession {
 public:
  FakeSafetySession(lcm::LCM* lcm, std::string supervisor_channel, std::string command_channel,
                    int64_t session_id = 4242, MessageAuthenticator auth = {})
      : lcm_(lcm),
        supervisor_channel_(std::move(supervisor_channel)),
        command_channel_(std::move(command_channel)),
        session_id_(session_id),
        auth_(std::move(auth)) {}

  /// Announces the session at stack time `utime` (supervisor_state_t, ARMED).
  void Announce(int64_t utime) {
    supervisor_state_t s{};
    s.utime = utime;
    s.seq = announcement_seq_++;
    s.sample_utime = utime;
    s.session_id = session_id_;
    s.state = supervisor_state_t::STATE_ARMED;
    auth_.Sign(&s);
    lcm_->publish(supervisor_channel_, &s);
    last_announced_utime_ = utime;
    announced_ = true;
  }

  /// Publishes `cmd` as this session's next command (session_id, seq, MAC
  /// set here), announcing the session first when due.
  void Publish(force_command_t cmd) {
    if (!announced_ || cmd.sample_utime - last_announced_utime_ >= 100'000) {
      Announce(cmd.sample_utime);
    }
    cmd.session_id = session_id_;
    cmd.seq = command_seq_++;
    auth_.Sign(&cmd);
    lcm_->publish(command_channel_, &cmd);
  }

  int64_t session_id() const { return session_id_; }
  /// The seq of the next command.
  int64_t next_seq() const { return command_seq_; }

 private:
  lcm::LCM* lcm_;
  std::string supervisor_channel_;
  std::string command_channel_;
  int64_t session_id_;
  MessageAuthenticator auth_;
  bool announced_ = false;
  int64_t last_announced_utime_ = 0;
  int64_t announcement_seq_ = 1;
  int64_t command_seq_ = 1;
};

}  // namespace stewart::test
