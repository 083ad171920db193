#include "stewart/node/supervisor_listener.h"

#include <algorithm>
#include <chrono>

namespace stewart {

SupervisorListener::SupervisorListener(const std::string& url, const std::string& channel,
                                       MessageAuthenticator* auth)
    : receiver_(url), auth_(auth) {
  receiver_.Subscribe(channel, &SupervisorListener::On, this);
}

bool SupervisorListener::WaitFor(double timeout_s,
                                 const std::function<bool(const supervisor_state_t&)>& accept,
                                 const std::function<bool()>& stop) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  has_match_ = false;
  accept_ = &accept;
  while (!has_match_ && !stop()) {
    const auto left_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                             end - std::chrono::steady_clock::now())
                             .count();
    if (left_ms <= 0) break;
    receiver_.HandleTimeout(static_cast<int>(std::min<int64_t>(left_ms, 50)));
  }
  accept_ = nullptr;
  return has_match_;
}

void SupervisorListener::On(const lcm::ReceiveBuffer*, const std::string&,
                            const supervisor_state_t* msg) {
  if (!auth_->Verify(*msg)) {
    ++forged_;
    return;
  }
  ++received_;
  latest_ = *msg;
  // The first answer in a drained batch wins: a later state in the same
  // batch may already name another operator's message.
  if (accept_ != nullptr && !has_match_ && (*accept_)(*msg)) {
    matched_ = *msg;
    has_match_ = true;
  }
}

}  // namespace stewart
