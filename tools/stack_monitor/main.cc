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
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_options.h"
#include "stewart/node/stop_signal.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/sensor_t.hpp"

namespace stewart {
namespace {

class Monitor {
 public:
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    health_[msg->name] = *msg;
  }
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* msg) {
    if (first_sample_utime_ < 0) first_sample_utime_ = msg->utime;
    newest_sample_utime_ = msg->utime;
  }
  void OnDiagnostics(const lcm::ReceiveBuffer*, const std::string&,
                     const safety_diagnostics_t* msg) {
    ++steps_;
    if (msg->active_case != safety_diagnostics_t::CASE_NONE) ++active_steps_;
    if (msg->infeasible) ++infeasible_steps_;
  }

  bool Seen(const std::string& name) const { return health_.count(name) > 0; }
  double SimTime() const {
    return first_sample_utime_ < 0
               ? 0.0
               : 1e-6 * static_cast<double>(newest_sample_utime_ - first_sample_utime_);
  }
  std::string Summary() const {
    std::ostringstream s;
    if (steps_ > 0) {
      s << "filter active " << (100 * active_steps_ / steps_) << "% of " << steps_ << " steps";
      if (infeasible_steps_ > 0) s << ", infeasible " << infeasible_steps_;
    }
    for (const auto& [name, h] : health_) {
      if (h.rejected_inputs > 0 || h.state >= health_t::STATE_DEGRADED) {
        s << " | " << name << ": state " << int{h.state} << ", rejected " << h.rejected_inputs;
        if (!h.last_error.empty()) s << " (" << h.last_error << ")";
      }
    }
    return s.str();
  }

 private:
  std::map<std::string, health_t> health_;
  int64_t first_sample_utime_ = -1;
  int64_t newest_sample_utime_ = 0;
  long steps_ = 0;
  long active_steps_ = 0;
  long infeasible_steps_ = 0;
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

  std::unique_ptr<lcm::LCM> lcm;
  try {
    lcm = stewart::MakeLcm(config.lcm.url);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  stewart::Monitor monitor;
  lcm->subscribe(config.lcm.channels.health, &stewart::Monitor::OnHealth, &monitor);
  if (progress_of_s > 0.0) {
    lcm->subscribe(config.lcm.channels.sensors, &stewart::Monitor::OnSensor, &monitor)
        ->setQueueCapacity(10000);
    lcm->subscribe(config.lcm.channels.safety_diagnostics, &stewart::Monitor::OnDiagnostics,
                   &monitor)
        ->setQueueCapacity(10000);
  }

  const auto start = std::chrono::steady_clock::now();
  auto next_print = start + std::chrono::seconds(1);
  const std::set<std::string> names = stewart::SplitNames(wait_for);
  while (!stewart::StopRequested()) {
    lcm->handleTimeout(100);
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
