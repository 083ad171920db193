#include "stewart/node/node_loop.h"

#include <spdlog/spdlog.h>

#include "stewart/node/operator_reset.h"
#include "stewart/node/stop_signal.h"

namespace stewart {

void ReportReceiverCounters(const LcmReceiver& receiver, HealthReporter* health) {
  health->SetCounter("rx_bad", receiver.counters().bad_datagrams);
  health->SetCounter("rx_decode_fail", receiver.counters().decode_failures);
  health->SetCounter("rx_incomplete", receiver.counters().incomplete_fragmented);
  health->SetCounter("rx_orphan_fragments", receiver.counters().orphan_fragments);
  // The kernel counts the datagrams its channel filter skipped (the other
  // processes' channels) among a socket's drops: with the filter attached
  // the count mixes those with what a full buffer lost, and goes out under a
  // name that says so. Without it (a recorder) it is the buffer's losses.
  health->SetCounter(
      receiver.kernel_filter_attached() ? "rx_kernel_skipped_or_dropped" : "rx_kernel_drops",
      receiver.counters().kernel_drops);
}

ExitCode RunNodeLoop(const std::string& name, lcm::LCM* lcm, LcmReceiver* receiver,
                     HealthReporter* health, int poll_ms, const std::function<bool()>& done) {
  // The operator's RESETs come through this receiver: no socket of their own.
  AttachOperatorResets(receiver);
  health->MaybePublish(lcm, true);
  while (!StopRequested()) {
    if (receiver->HandleTimeout(poll_ms) < 0 && !StopRequested()) {
      spdlog::error("{}: LCM receive failed", name);
      health->SetState(health_t::STATE_FAULT);
      health->MaybePublish(lcm, true);
      return ExitCode::kFault;
    }
    ReportReceiverCounters(*receiver, health);
    health->MaybePublish(lcm);
    if (done && done()) break;
  }
  health->SetState(health_t::STATE_STOPPED);
  health->MaybePublish(lcm, true);
  return ExitCode::kOk;
}

}  // namespace stewart
