// stewart_cpu_stall_check: can this machine hold a 1 kHz loop? Spins on one
// CPU reading the clock and counts the gaps in which the thread did not run
// at all. A thread that never sleeps and makes no system call can only be
// stopped by interrupts, by the kernel's own non-preemptible work or by the
// hypervisor, so every gap it sees is one the control loop would see too,
// whatever the stack does. Run it as the loop runs (tools/launch.sh
// --realtime): chrt -f 50 taskset -c 1 build/tools/stewart_cpu_stall_check
// (docs/operations.md, "Real-time scheduling"). It spins in chunks with short
// sleeps so SCHED_FIFO's throttling (95 % per second) never cuts in.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <thread>

int main(int argc, char** argv) {
  CLI::App app{"Count the gaps in which a spinning thread did not run (machine qualification)"};
  double seconds = 20.0;
  double threshold_ms = 0.5;
  app.add_option("-t,--seconds", seconds, "seconds of spinning")->capture_default_str();
  app.add_option("--threshold-ms", threshold_ms, "a gap longer than this is counted")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  using Clock = std::chrono::steady_clock;
  const auto threshold = std::chrono::duration<double, std::milli>(threshold_ms);
  const auto chunk = std::chrono::milliseconds(450);
  long gaps = 0;
  Clock::duration worst{};
  const Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(seconds));
  Clock::duration spun{};
  while (Clock::now() < end) {
    Clock::time_point previous = Clock::now();
    const Clock::time_point chunk_end = previous + chunk;
    for (;;) {
      const Clock::time_point t = Clock::now();
      if (t >= chunk_end) break;
      const Clock::duration gap = t - previous;
      if (gap > threshold) ++gaps;
      if (gap > worst) worst = gap;
      previous = t;
    }
    spun += chunk;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const double spun_s = std::chrono::duration<double>(spun).count();
  std::printf("%.1f s spinning: %ld gaps longer than %.2f ms (%.2f per s), longest %.3f ms\n",
              spun_s, gaps, threshold_ms, gaps / spun_s,
              std::chrono::duration<double, std::milli>(worst).count());
  return 0;
}
