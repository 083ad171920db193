// stewart_stack_monitor: watches a running stack over LCM (read-only).
//
//   --wait-for estimator,controller,safety   exit 0 once each has sent a
//                                             heartbeat (exit 1 on timeout)
//   --progress-of 40                          print a progress line every
//                                             second: simulated time of the
//                                             newest sensor sample, filter
//                                             activity, rejections
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "stewart/health_t.hpp"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/node_options.h"
#include "stewart/node/stop_signal.h"

namespace stewart {
namespace {

class Monitor {
 public:
  // Progress comes from the heartbeats alone (2 Hz by default), not from the
  // 1 kHz streams: a monitor must not compete with the loop for the CPUs.
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    health_[msg->name] = *msg;
    // Two heartbeats can come between two progress lines: the worst of them.
    int8_t& worst = worst_since_print_.try_emplace(msg->name, msg->worst_state).first->second;
    if (Severity(msg->worst_state) >= Severity(worst)) worst = msg->worst_state;
    if ((msg->name == "plant_sim" || msg->name == "hw_bridge") && msg->sample_utime > 0) {
      if (first_sample_utime_ < 0) first_sample_utime_ = msg->sample_utime;
      newest_sample_utime_ = msg->sample_utime;
    }
  }

  bool Seen(const std::string& name) const { return health_.count(name) > 0; }
  double SimTime() const {
    return first_sample_utime_ < 0
               ? 0.0
               : 1e-6 * static_cast<double>(newest_sample_utime_ - first_sample_utime_);
  }
  /// The progress line's text; starts the next period of the worst states.
  std::string Summary() {
    std::ostringstream s;
    const auto safety = health_.find("safety");
    if (safety != health_.end() && safety->second.messages_out > 0) {
      const health_t& h = safety->second;
      const int64_t steps = h.messages_out;
      s << "filter active " << (100 * Counter(h, "active_steps") / steps) << "% of " << steps
        << " steps";
      if (Counter(h, "infeasible") > 0) s << ", infeasible " << Counter(h, "infeasible");
    }
    for (const auto& [name, h] : health_) {
      const int8_t worst = worst_since_print_.count(name) ? worst_since_print_.at(name) : h.state;
      if (h.rejected_inputs > 0 || Severity(worst) > 0 || h.fault_latched) {
        s << " | " << name << ": state " << StateName(h.state);
        if (worst != h.state) s << " (" << StateName(worst) << " since the last line)";
        if (h.fault_latched) s << ", FAULT latched (" << h.latched_error << ")";
        s << ", rejected " << h.rejected_inputs << " (+" << h.rejected_inputs_delta << ")";
        if (!h.last_error.empty()) s << " (" << h.last_error << ")";
      }
    }
    for (auto& [name, worst] : worst_since_print_) worst = health_.at(name).state;
    return s.str();
  }

 private:
  /// FAULT 2, DEGRADED 1, the others 0 (as health_state::Severity).
  static int Severity(int8_t state) {
    return state == health_t::STATE_FAULT ? 2 : state == health_t::STATE_DEGRADED ? 1 : 0;
  }
  static const char* StateName(int8_t state) {
    static const char* const kNames[] = {"starting", "ok", "DEGRADED", "FAULT", "stopped"};
    return state >= 0 && state <= 4 ? kNames[state] : "?";
  }
  static int64_t Counter(const health_t& h, const std::string& name) {
    for (int i = 0; i < h.num_counters; ++i) {
      if (h.counter_names[static_cast<size_t>(i)] == name) {
        return h.counter_values[static_cast<size_t>(i)];
      }
    }
    return 0;
  }

  std::map<std::string, health_t> health_;
  std::map<std::string, int8_t> worst_since_print_;
  int64_t first_sample_utime_ = -1;
  int64_t newest_sample_utime_ = 0;
};

std::set<std::string> SplitNames(const std::string& csv) {
  std::set<std::string> names;
  std::stringstream in(csv);
  for (std::string name; std::getline(in, name, ',');) {
    if (!name.empty()) names.insert(name);
  }
  return names;
}

}  // namespace
}  // namespace stewart

int main(int argc, char** argv) {
  CLI::App app{"Watch a running stewart stack over LCM (read-only)"};
  stewart::NodeOptions options;
  stewart::AddNodeOptions(&app, &options);
  std::string wait_for;
  double timeout_s = 10.0;
  double progress_of_s = 0.0;
  app.add_option("--wait-for", wait_for, "comma-separated process names to wait for");
  app.add_option("--timeout", timeout_s, "seconds to wait for --wait-for")->capture_default_str();
  app.add_option("--progress-of", progress_of_s,
                 "print progress once a second against this many simulated seconds");
  CLI11_PARSE(app, argc, argv);
  const stewart::StackConfig config = stewart::LoadNodeConfigOrExit(options);
  stewart::InstallStopSignalHandlers();

  std::unique_ptr<stewart::LcmReceiver> receiver_ptr;
  try {
    receiver_ptr = std::make_unique<stewart::LcmReceiver>(config.lcm.url);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  stewart::Monitor monitor;
  stewart::LcmReceiver& receiver = *receiver_ptr;
  receiver.Subscribe(config.lcm.channels.health, &stewart::Monitor::OnHealth, &monitor);

  const auto start = std::chrono::steady_clock::now();
  auto next_print = start + std::chrono::seconds(1);
  const std::set<std::string> names = stewart::SplitNames(wait_for);
  while (!stewart::StopRequested()) {
    receiver.HandleTimeout(100);
    const auto now = std::chrono::steady_clock::now();
    if (!names.empty()) {
      bool all = true;
      for (const auto& name : names) all = all && monitor.Seen(name);
      if (all) return 0;
      if (now - start > std::chrono::duration<double>(timeout_s)) {
        std::string missing;
        for (const auto& name : names) {
          if (!monitor.Seen(name)) missing += " " + name;
        }
        spdlog::error("no heartbeat within {} s from:{}", timeout_s, missing);
        return 1;
      }
      continue;
    }
    if (progress_of_s > 0.0 && now >= next_print) {
      next_print += std::chrono::seconds(1);
      const double wall = std::chrono::duration<double>(now - start).count();
      std::printf("  t = %6.2f / %.0f s simulated (%4.1fx real time)  %s\n", monitor.SimTime(),
                  progress_of_s, wall > 0 ? monitor.SimTime() / wall : 0.0,
                  monitor.Summary().c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}
