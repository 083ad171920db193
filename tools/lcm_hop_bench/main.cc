// stewart_lcm_hop_bench: what one hop of the control loop costs on this
// machine (docs/performance.md, "LCM hop"). A child process answers every
// force_command_t on PING with one on PONG; the parent measures round trips.
// Both receive sides are measured in one run, so compare their ratio:
//   lcm       lcm::LCM::subscribe + handleTimeout (LCM's receive thread)
//   receiver  stewart::LcmReceiver (the nodes' receive path)
// Publishing is lcm::LCM::publish in both. Each is measured with the two
// processes free to run on any CPU and pinned together to one CPU (what
// tools/launch.sh does with the loop: --loop-cpu). Private URL, ttl=0.
#include <sched.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "stewart/force_command_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

struct Echo {
  lcm::LCM* lcm;
  void On(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
    lcm->publish("PONG", msg);
  }
};

struct Counter {
  int64_t received = 0;
  void On(const lcm::ReceiveBuffer*, const std::string&, const force_command_t*) { ++received; }
};

[[noreturn]] void RunEcho(const std::string& url, bool use_receiver) {
  auto lcm = MakeLcm(url);
  Echo echo{lcm.get()};
  if (use_receiver) {
    LcmReceiver receiver(url);
    receiver.Subscribe("PING", &Echo::On, &echo);
    for (;;) receiver.HandleTimeout(1000);
  }
  lcm->subscribe("PING", &Echo::On, &echo);
  for (;;) lcm->handleTimeout(1000);
}

void PinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  sched_setaffinity(0, sizeof(set), &set);
}

void Unpin() {
  cpu_set_t set;
  CPU_ZERO(&set);
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  for (long c = 0; c < cpus; ++c) CPU_SET(static_cast<int>(c), &set);
  sched_setaffinity(0, sizeof(set), &set);
}

// Round trips in microseconds, sorted. cpu >= 0: both processes on that CPU.
std::vector<double> Measure(const std::string& url, bool use_receiver, int round_trips, int cpu) {
  if (cpu >= 0) {
    PinTo(cpu);
  } else {
    Unpin();
  }
  const pid_t child = fork();  // inherits the affinity
  if (child == 0) RunEcho(url, use_receiver);
  auto lcm = MakeLcm(url);
  Counter counter;
  std::unique_ptr<LcmReceiver> receiver;
  if (use_receiver) {
    receiver = std::make_unique<LcmReceiver>(url);
    receiver->Subscribe("PONG", &Counter::On, &counter);
  } else {
    lcm->subscribe("PONG", &Counter::On, &counter);
  }
  auto handle = [&](int ms) {
    return use_receiver ? receiver->HandleTimeout(ms) : lcm->handleTimeout(ms);
  };
  force_command_t ping{};
  // Until the child answers (it may still be starting).
  for (int tries = 0; counter.received == 0 && tries < 500; ++tries) {
    lcm->publish("PING", &ping);
    handle(10);
  }
  while (handle(50) > 0) {
  }
  std::vector<double> rtt_us;
  for (int i = 0; i < round_trips; ++i) {
    const int64_t before = counter.received;
    ping.seq = i;
    const Clock::time_point start = Clock::now();
    lcm->publish("PING", &ping);
    while (counter.received == before) {
      if (handle(1000) <= 0 && counter.received == before) break;  // lost: skip it
    }
    if (counter.received > before) {
      rtt_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    }
  }
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  std::sort(rtt_us.begin(), rtt_us.end());
  return rtt_us;
}

double At(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  return sorted[std::min(sorted.size() - 1, static_cast<size_t>(p * sorted.size()))];
}

}  // namespace
}  // namespace stewart

int main(int argc, char** argv) {
  CLI::App app{"Round trip of one LCM message between two processes: lcm::LCM vs LcmReceiver"};
  int round_trips = 5000;
  int port = 7899;
  app.add_option("-n,--round-trips", round_trips, "round trips per receive side")
      ->capture_default_str();
  app.add_option("--port", port, "private multicast port (ttl=0)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    const std::string url = stewart::PrivateLcmUrl(port);
    const int last_cpu = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)) - 1;
    std::printf("%-9s %-6s %10s %10s %10s %8s   (round trip = 2 hops, us)\n", "receive", "cpus",
                "mean", "p50", "p99", "n");
    double p50[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
    for (int pinned = 0; pinned < 2; ++pinned) {
      for (int r = 0; r < 2; ++r) {
        const bool use_receiver = r == 1;
        const std::vector<double> rtt =
            stewart::Measure(url, use_receiver, round_trips, pinned ? last_cpu : -1);
        double mean = 0.0;
        for (double v : rtt) mean += v;
        mean /= static_cast<double>(std::max<size_t>(rtt.size(), 1));
        p50[pinned][r] = stewart::At(rtt, 0.5);
        const std::string cpus = pinned ? "cpu " + std::to_string(last_cpu) : "any";
        std::printf("%-9s %-6s %10.1f %10.1f %10.1f %8zu\n", use_receiver ? "receiver" : "lcm",
                    cpus.c_str(), mean, p50[pinned][r], stewart::At(rtt, 0.99), rtt.size());
      }
    }
    auto ratio = [](double a, double b) { return b > 0.0 ? a / b : 0.0; };
    std::printf(
        "p50 ratios: lcm / receiver %.2f (any CPU), %.2f (one CPU); lcm on any CPU / "
        "receiver on one CPU %.2f\n",
        ratio(p50[0][0], p50[0][1]), ratio(p50[1][0], p50[1][1]), ratio(p50[0][0], p50[1][1]));
  } catch (const std::exception& e) {
    spdlog::error("stewart_lcm_hop_bench: {}", e.what());
    return 1;
  }
  return 0;
}
