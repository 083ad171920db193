#include "stewart/node/operator_reset.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>

namespace stewart {

OperatorResetFilter::OperatorResetFilter(MessageAuthenticator auth, double window_s)
    : auth_(std::move(auth)), window_us_(std::llround(window_s * 1e6)) {}

bool OperatorResetFilter::OnCommand(const operator_command_t& msg, int64_t receive_wall_us) {
  if (msg.command != operator_command_t::COMMAND_RESET) return false;
  if (msg.operator_id == 0) {  // never a console's id
    ++counts_.rejected_invalid;
    return false;
  }
  if (!auth_.Verify(msg)) {
    ++counts_.rejected_auth;
    return false;
  }
  // Both are wall clocks here (the operator's console and this host), so
  // the bus's window bounds their difference.
  if (msg.utime < receive_wall_us - window_us_ || msg.utime > receive_wall_us + window_us_) {
    ++counts_.rejected_time;
    return false;
  }
  OperatorSeq* slot = nullptr;
  for (OperatorSeq& s : last_seq_) {
    if (s.operator_id == msg.operator_id) slot = &s;
  }
  if (slot != nullptr && msg.seq <= slot->seq) {
    ++counts_.rejected_replay;
    return false;
  }
  if (slot == nullptr) {
    slot = &last_seq_[next_slot_];
    next_slot_ = (next_slot_ + 1) % last_seq_.size();
    slot->operator_id = msg.operator_id;
  }
  slot->seq = msg.seq;
  ++counts_.accepted;
  return true;
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
