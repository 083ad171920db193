#pragma once
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"

namespace stewart {

/// The event loop of a message-driven node: handles the receiver's traffic
/// (the operator's RESETs included, operator_reset.h) and beats the
/// heartbeat (published through `lcm`) until a stop signal or until
/// `done()` returns true. A
/// receive error reports FAULT and returns kFault; a clean stop reports
/// STOPPED and returns kOk. A stop signal interrupting the wait (EINTR) is a clean stop.
/// Puts the receiver's counts of unusable input into the heartbeat:
/// rx_bad (datagrams that are not valid LCM), rx_decode_fail (messages
/// on a subscribed channel that did not decode as its type),
/// rx_incomplete (fragmented messages given up: a fragment lost, too old, or
/// no room under the receiver's bounds) and rx_orphan_fragments (fragments
/// of a message whose first fragment was not kept).
void ReportReceiverCounters(const LcmReceiver& receiver, HealthReporter* health);

ExitCode RunNodeLoop(const std::string& name, lcm::LCM* lcm, LcmReceiver* receiver,
                     HealthReporter* health, int poll_ms, const std::function<bool()>& done = {});

}  // namespace stewart
