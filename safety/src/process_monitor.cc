#include "stewart/safety/process_monitor.h"

#include <sstream>

namespace stewart::safety {
namespace {

// health_t::STATE_* (common/health_counters.h's health_state).
constexpr int8_t kOk = 1;
constexpr int8_t kDegraded = 2;
constexpr int8_t kFault = 3;

}  // namespace

ProcessMonitor::ProcessMonitor(const std::vector<std::string>& required, int64_t timeout_us)
    : timeout_us_(timeout_us) {
  for (const std::string& requirement : required) {
    std::stringstream alternatives(requirement);
    for (std::string name; std::getline(alternatives, name, '|');) {
      if (!name.empty()) processes_.push_back(Process{name, groups_});
    }
    ++groups_;
  }
  unheard_reported_.assign(groups_, false);
}

void ProcessMonitor::SetMoving(bool moving, int64_t wall_us) {
  if (moving && !moving_) moving_since_us_ = wall_us;
  if (!moving) unheard_reported_.assign(groups_, false);
  moving_ = moving;
}

std::string ProcessMonitor::OnHeartbeat(const std::string& name, int8_t state, int64_t seq,
                                        int64_t wall_us) {
  for (Process& p : processes_) {
    if (p.name != name) continue;
    std::string fault;
    if (p.seen && seq < p.seq) fault = name + " restarted";
    if (state == kFault && (!p.seen || p.state != kFault)) {
      fault = fault.empty() ? name + " reported FAULT" : fault + " and reported FAULT";
    }
    p.seen = true;
    p.silent_reported = false;
    p.state = state;
    p.seq = seq;
    p.wall_us = wall_us;
    return fault;
  }
  return "";
}

std::vector<std::string> ProcessMonitor::CheckSilence(int64_t wall_us) {
  std::vector<std::string> faults;
  for (Process& p : processes_) {
    if (!p.seen || p.silent_reported || wall_us - p.wall_us <= timeout_us_) continue;
    p.silent_reported = true;
    faults.push_back(p.name + " heartbeat lost");
  }
  if (!moving_ || wall_us - moving_since_us_ <= timeout_us_) return faults;
  for (size_t g = 0; g < groups_; ++g) {
    bool heard = false;
    std::string names;
    for (const Process& p : processes_) {
      if (p.group != g) continue;
      heard = heard || p.seen;
      names += (names.empty() ? "" : " or ") + p.name;
    }
    if (heard || unheard_reported_[g]) continue;
    unheard_reported_[g] = true;
    faults.push_back("no heartbeat from " + names + " since the platform started moving");
  }
  return faults;
}

bool ProcessMonitor::Healthy(int64_t wall_us, std::string* why_not) const {
  for (size_t g = 0; g < groups_; ++g) {
    bool ok = false;
    std::string names;
    for (const Process& p : processes_) {
      if (p.group != g) continue;
      names += (names.empty() ? "" : " or ") + p.name;
      ok = ok || (p.seen && wall_us - p.wall_us <= timeout_us_ &&
                  (p.state == kOk || p.state == kDegraded));
    }
    if (!ok) {
      if (why_not != nullptr) *why_not = "no healthy heartbeat from " + names;
      return false;
    }
  }
  return true;
}

}  // namespace stewart::safety
