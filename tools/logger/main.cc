// stewart_logger: records every channel on an LCM URL into an LCM log file,
// in the format lcm-logger writes (lcm-logplayer, lcm-spy, stewart_log_export
// and stewart_replay read it).
//
// Why not lcm-logger: 1.3.1 subscribes with LCM's default 30-message queue
// and silently drops bursts whenever it is descheduled (docs/operations.md,
// "Logging"), and like every lcm::LCM receiver it is woken twice per
// message. This one reads the
// socket itself (stewart::LcmReceiver) in batches: it sleeps --batch-ms
// between reads and takes everything the kernel queued meanwhile (the socket
// buffer, recv_buf_size on the URL, holds seconds of the stack's traffic),
// so it wakes a few hundred times a second instead of 14 000 and leaves the
// CPUs to the control loop. Each event keeps the kernel's arrival time of its
// datagram (SO_TIMESTAMP), not the time of the batch. It drains the socket
// before it exits and reports what it wrote.
//
// A restarted logger continues its log with --append, so that the log's check
// (stewart_log_export --check) names what was lost while none ran, as gaps
// in every stream, instead of a second file starting without them or -f
// overwriting the first.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>

#include "stewart/node/lcm_receiver.h"
#include "stewart/node/stop_signal.h"

namespace {

class Recorder {
 public:
  Recorder(lcm::LogFile* log, std::regex channels) : log_(log), channels_(std::move(channels)) {}

  void OnMessage(const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
    if (!Wanted(channel)) return;
    lcm::LogEvent event;
    event.eventnum = written_;
    event.timestamp = rbuf.recv_utime;
    event.channel = channel;
    event.datalen = static_cast<int32_t>(rbuf.data_size);
    event.data = rbuf.data;
    if (log_->writeEvent(&event) == 0) {
      ++written_;
    } else {
      ++failed_;
    }
  }

  int64_t written() const { return written_; }
  int64_t failed() const { return failed_; }

 private:
  // As LCM matches a subscription: the whole channel name against the regex.
  bool Wanted(const std::string& channel) {
    auto it = wanted_.find(channel);
    if (it == wanted_.end())
      it = wanted_.emplace(channel, std::regex_match(channel, channels_)).first;
    return it->second;
  }

  lcm::LogFile* log_;
  std::regex channels_;
  std::unordered_map<std::string, bool> wanted_;
  int64_t written_ = 0;
  int64_t failed_ = 0;
};

/// The length of `path` up to the end of its last complete event: a logger
/// killed mid-write leaves a cut event, after which LCM's reader stops, so
/// an appended log must start where the complete ones end.
long CompleteLength(const std::string& path) {
  lcm::LogFile log(path, "r");
  if (!log.good()) return -1;
  long end = 0;
  while (log.readNextEvent() != nullptr) end = std::ftell(log.getFilePtr());
  return end;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Record every LCM channel to a log file (lcm-logger format, no silent drops)"};
  std::string url, file, channels = ".*";
  double flush_s = 0.0;
  int batch_ms = 2;
  bool force = false;
  bool append = false;
  app.add_option("--lcm-url", url, "LCM URL (udpm://; default: LCM's default)");
  app.add_option("-c,--channel", channels, "channel regex (the whole name must match)")
      ->capture_default_str();
  app.add_option("--batch-ms", batch_ms, "milliseconds slept between reads of the socket")
      ->capture_default_str();
  app.add_option("--flush-interval", flush_s,
                 "seconds between flushes (0: after every batch, small writes a stock kernel does "
                 "not hold a real-time task behind)")
      ->capture_default_str();
  app.add_flag("-f,--force", force, "overwrite FILE");
  app.add_flag("-a,--append", append,
               "continue FILE if it exists (a restarted logger): the time it did not run shows "
               "as gaps in stewart_log_export --check")
      ->excludes("--force");
  app.add_option("file", file, "log file")->required();
  CLI11_PARSE(app, argc, argv);

  const bool exists = std::filesystem::exists(file);
  if (!force && !append && exists) {
    spdlog::error("stewart_logger: {} exists (use -f to overwrite, -a to continue it)", file);
    return 2;
  }
  if (append && exists) {
    const long complete = CompleteLength(file);
    std::error_code error;
    const auto size = std::filesystem::file_size(file, error);
    if (complete < 0 || error) {
      spdlog::error("stewart_logger: cannot read {} to continue it", file);
      return 2;
    }
    if (static_cast<std::uintmax_t>(complete) < size) {
      spdlog::warn("stewart_logger: {}: {} bytes of a cut last event dropped before continuing",
                   file, size - static_cast<std::uintmax_t>(complete));
      std::filesystem::resize_file(file, static_cast<std::uintmax_t>(complete), error);
      if (error) {
        spdlog::error("stewart_logger: cannot cut {}: {}", file, error.message());
        return 2;
      }
    }
  }
  std::regex channel_regex;
  try {
    channel_regex = std::regex(channels);
  } catch (const std::regex_error& e) {
    spdlog::error("stewart_logger: bad channel regex '{}': {}", channels, e.what());
    return 2;
  }
  std::unique_ptr<stewart::LcmReceiver> receiver;
  try {
    receiver = std::make_unique<stewart::LcmReceiver>(url);
  } catch (const std::exception& e) {
    spdlog::error("stewart_logger: {}", e.what());
    return 1;
  }
  lcm::LogFile log(file, append ? "a" : "w");
  if (!log.good()) {
    spdlog::error("stewart_logger: cannot write {}", file);
    return 2;
  }
  Recorder recorder(&log, std::move(channel_regex));
  receiver->SubscribeAll([&](const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
    recorder.OnMessage(rbuf, channel);
  });
  stewart::InstallStopSignalHandlers();
  spdlog::info("stewart_logger: {} -> {}{}", url.empty() ? "default URL" : url, file,
               append && exists ? " (continued)" : "");
  const auto flush_every = std::chrono::duration<double>(flush_s);
  auto last_flush = std::chrono::steady_clock::now();
  int64_t drops_reported = 0;
  while (!stewart::StopRequested()) {
    if (receiver->HandleTimeout(100) < 0) {
      spdlog::error("stewart_logger: receive failed");
      break;
    }
    const int64_t drops = receiver->counters().kernel_drops;
    if (drops > drops_reported) {
      // The log misses these datagrams: say so when it happens, not only at the end.
      spdlog::warn(
          "stewart_logger: the kernel dropped {} datagrams so far (socket buffer full: raise "
          "recv_buf_size on the URL and net.core.rmem_max)",
          drops);
      drops_reported = drops;
    }
    const auto now = std::chrono::steady_clock::now();
    if (now - last_flush >= flush_every) {
      std::fflush(log.getFilePtr());
      last_flush = now;
    }
    if (batch_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(batch_ms));
  }
  while (receiver->HandleTimeout(0) > 0) {  // drain what arrived before the stop
  }
  std::fflush(log.getFilePtr());
  const stewart::LcmReceiverCounters& c = receiver->counters();
  spdlog::info(
      "stewart_logger: {} messages written, {} failed ({} datagrams read, {} not LCM, "
      "{} fragmented messages incomplete, {} dropped by the kernel)",
      recorder.written(), recorder.failed(), c.datagrams, c.bad_datagrams, c.incomplete_fragmented,
      c.kernel_drops);
  return recorder.failed() == 0 ? 0 : 1;
}
