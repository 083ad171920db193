#include "stewart/node/operator_reset.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>

namespace stewart {

OperatorResetFilter::OperatorResetFilter(MessageAuthenticator auth, double window_s)
    : auth_(std::move(auth)), check_(std::llround(window_s * 1e6)) {}

bool OperatorResetFilter::OnCommand(const operator_command_t& msg, int64_t receive_wall_us) {
  if (msg.command != operator_command_t::COMMAND_RESET) return false;
  // Both clocks are wall clocks here (the operator's console and this host),
  // so the bus's time window bounds their difference.
  switch (check_.Check(msg.operator_id, msg.seq, msg.utime, auth_.Verify(msg), receive_wall_us)) {
    case OperatorVerdict::kAccepted:
      ++counts_.accepted;
      return true;
    case OperatorVerdict::kUnauthentic:
      ++counts_.rejected_auth;
      return false;
    case OperatorVerdict::kZeroOperator:
      ++counts_.rejected_invalid;
      return false;
    case OperatorVerdict::kStale:
      ++counts_.rejected_time;
      return false;
    case OperatorVerdict::kSeqNotIncreasing:
      ++counts_.rejected_replay;
      return false;
  }
  return false;
}

bool AcceptActuatorReset(const operator_command_t& msg, bool authentic, int64_t wall_now_us,
                         OperatorCommandCheck* check, HealthCounters* counters) {
  if (msg.command != operator_command_t::COMMAND_RESET) return false;
  counters->CountIn();
  const OperatorVerdict v =
      check->Check(msg.operator_id, msg.seq, msg.utime, authentic, wall_now_us);
  if (v == OperatorVerdict::kAccepted) return true;
  counters->Reject(ToString(v), "operator_command_t RESET from " + std::to_string(msg.operator_id) +
                                    ", seq " + std::to_string(msg.seq));
  return false;
}

OperatorResets::OperatorResets(const LcmConfig& lcm)
    : url_(lcm.url),
      channel_(lcm.channels.operator_command),
      filter_(MessageAuthenticator::FromKeyFile(lcm.auth_key_file),
              lcm.time_plausibility.window_s) {}

void OperatorResets::Attach(LcmReceiver* receiver) {
  receiver->Subscribe(channel_, &OperatorResets::OnOperator, this);
  attached_ = true;
}

OperatorResetCounts OperatorResets::Poll() {
  if (!attached_) {
    if (!own_receiver_) {
      own_receiver_ = std::make_unique<LcmReceiver>(url_);
      own_receiver_->Subscribe(channel_, &OperatorResets::OnOperator, this);
    }
    while (own_receiver_->HandleTimeout(0) > 0) {
    }
  }
  return filter_.counts();
}

void OperatorResets::OnOperator(const lcm::ReceiveBuffer* rbuf, const std::string&,
                                const operator_command_t* msg) {
  if (filter_.OnCommand(*msg, rbuf->recv_utime)) {
    spdlog::info("operator {} RESET (seq {}): latched faults acknowledged", msg->operator_id,
                 msg->seq);
  }
}

namespace {
std::unique_ptr<OperatorResets>& Installed() {
  static std::unique_ptr<OperatorResets> resets;
  return resets;
}
}  // namespace

void InstallOperatorResetListener(const LcmConfig& lcm) {
  Installed() = std::make_unique<OperatorResets>(lcm);
}

void AttachOperatorResets(LcmReceiver* receiver) {
  if (Installed()) Installed()->Attach(receiver);
}

OperatorResetCounts PollOperatorResets() {
  OperatorResets* resets = Installed().get();
  return resets == nullptr ? OperatorResetCounts{} : resets->Poll();
}

}  // namespace stewart
