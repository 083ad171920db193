#pragma once
// LCM messages and logs in tests: a message appended to an LCM log file as
// the logger would record it, the variable-length barrier groups of a
// safety_diagnostics_t filled in one call, and the messages a test receives.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <utility>
#include <vector>

#include "stewart/safety/diagnostics_lcm.h"
#include "stewart/safety_diagnostics_t.hpp"

namespace stewart::test {

/// Encodes `msg` and appends it to `log` on `channel` at `timestamp` (us).
template <typename Msg>
void AppendToLog(lcm::LogFile* log, const std::string& channel, const Msg& msg, int64_t timestamp) {
  std::vector<uint8_t> buffer(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
  lcm::LogEvent event{};
  event.timestamp = timestamp;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(buffer.size());
  event.data = buffer.data();
  ASSERT_EQ(log->writeEvent(&event), 0);
}

/// One barrier group of safety_diagnostics_t: per barrier its name, h,
/// alpha(h), LSE weight and multiplier.
struct DiagnosticsGroup {
  std::vector<std::string> names;
  std::vector<double> h, alpha_h, w, mu;
};

/// Sets both groups and their counts.
inline void SetGroups(const DiagnosticsGroup& position, const DiagnosticsGroup& velocity,
                      safety_diagnostics_t* d) {
  for (const auto& [group, fields] : {std::pair{&position, safety::PositionGroup(d)},
                                      std::pair{&velocity, safety::VelocityGroup(d)}}) {
    *fields.num = static_cast<int32_t>(group->names.size());
    *fields.names = group->names;
    *fields.h = group->h;
    *fields.alpha_h = group->alpha_h;
    *fields.w = group->w;
    *fields.mu = group->mu;
  }
}

/// Every message of one type a subscription received, in order:
/// `lcm->subscribe(channel, &Inbox<Msg>::On, &inbox)`.
template <typename Msg>
struct Inbox {
  void On(const lcm::ReceiveBuffer*, const std::string&, const Msg* msg) {
    received.push_back(*msg);
  }
  std::vector<Msg> received;
};

/// Handles `lcm`'s messages until `done()` or `timeout_s` has passed:
/// whether `done()`.
template <typename Done>
bool HandleUntil(lcm::LCM* lcm, Done done, double timeout_s, int step_ms = 20) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(timeout_s));
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    lcm->handleTimeout(step_ms);
  }
  return true;
}

}  // namespace stewart::test
