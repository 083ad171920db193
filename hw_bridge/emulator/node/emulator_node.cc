#include "emulator_node.h"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "stewart/common/check.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/stop_signal.h"
#include "stewart/state_t.hpp"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

/// Waits until fd is readable or `deadline` passes, with the timer's
/// precision rather than poll()'s milliseconds: no busy wait before a tick.
bool WaitReadable(int fd, Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - Clock::now());
  if (left.count() <= 0) return false;
  pollfd pfd{fd, POLLIN, 0};
  timespec timeout{};
  timeout.tv_sec = static_cast<time_t>(left.count() / 1'000'000'000);
  timeout.tv_nsec = static_cast<long>(left.count() % 1'000'000'000);
  return ppoll(&pfd, 1, &timeout, nullptr) > 0;
}

/// Whether fd has something to read now.
bool Readable(int fd) {
  pollfd pfd{fd, POLLIN, 0};
  return poll(&pfd, 1, 0) > 0 && (pfd.revents & POLLIN) != 0;
}

hw::PlantBackendOptions BackendOptions(bool noise) {
  hw::PlantBackendOptions o;
  o.noise = noise;
  return o;
}

}  // namespace

uint64_t EmulatorPeriodUs(double rate_hz) {
  const auto period_us = static_cast<uint64_t>(std::llround(1e6 / rate_hz));
  if (period_us == 0) {
    throw InputError("--rate-hz", std::to_string(rate_hz) + " Hz is too high (period < 1 us)");
  }
  return period_us;
}

EmulatorNode::EmulatorNode(const StackConfig& config, const PlantTruth& truth, lcm::LCM* lcm,
                           const EmulatorOptions& options)
    : config_(config),
      lcm_(lcm),
      options_(options),
      backend_(config, truth, BackendOptions(options.noise)),
      device_(&backend_),
      schedule_(EmulatorPeriodUs(options.rate_hz), options.drop_every),
      reader_(options.transport != "pty") {
  const HwBridgeConfig& hw = config.hw_bridge;
  if (options_.transport == "pty") {
    pty_ = std::make_unique<hw::PtyDevice>();
    link_ = pty_->master();
    if (!options_.pty_link.empty()) {
      unlink(options_.pty_link.c_str());
      if (symlink(pty_->slave_path().c_str(), options_.pty_link.c_str()) != 0) {
        throw std::runtime_error("cannot create symlink " + options_.pty_link);
      }
    }
    std::printf("PTY %s\n", pty_->slave_path().c_str());
    std::fflush(stdout);
  } else {
    udp_ = std::make_unique<hw::UdpTransport>(
        options_.bind_host.empty() ? hw.device_host : options_.bind_host,
        options_.device_port >= 0 ? options_.device_port : hw.device_port,
        options_.host.empty() ? hw.local_host : options_.host,
        options_.host_port >= 0 ? options_.host_port : hw.local_port);
    link_ = udp_.get();
  }
  spdlog::info("hw_emulator: {} at {} Hz{}",
               pty_ ? "pty " + pty_->slave_path() : link_->description(), options_.rate_hz,
               lcm_ ? "; ground truth -> " + config.lcm.channels.state_truth : "");
}

uint64_t EmulatorNode::DeviceNow() const {
  return hw::SampleSchedule::kDeviceEpochUs +
         static_cast<uint64_t>(
             std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_).count());
}

void EmulatorNode::Tick(uint64_t now_us) {
  const hw::SampleSchedule::Sample sample = schedule_.Take(now_us);
  const hw::SensorFrame frame = device_.Tick(sample.time_us);
  if (sample.send) {
    const std::size_t size = hw::EncodeSensorFrame(frame, tx_.data());
    link_->Send(tx_.data(), size);
  }
  if (lcm_ != nullptr) {
    state_t truth{};
    truth.utime =
        start_epoch_us_ + static_cast<int64_t>(sample.time_us - hw::SampleSchedule::kDeviceEpochUs);
    truth.seq = frame.seq;  // = sensor_t.seq the bridge publishes for this sample
    truth.sample_utime = truth.utime;
    ToArray(backend_.q(), truth.q);
    ToArray(backend_.qd(), truth.qd);
    truth.status = state_t::STATUS_VALID | state_t::STATUS_GROUND_TRUTH;
    lcm_->publish(config_.lcm.channels.state_truth, &truth);
  }
}

void EmulatorNode::OnFrame(const hw::DecodedFrame& frame, uint64_t rx_us) {
  if (frame.type == hw::FrameType::kCommand) {
    const uint32_t was = device_.sessions().session();
    const hw::CommandAcceptance verdict = device_.OnCommandFrame(frame.command, rx_us);
    if (verdict == hw::CommandAcceptance::kAdopted) {
      spdlog::info("hw_emulator: following link session {} from seq {} (was {})",
                   frame.command.session, frame.command.seq, was);
    } else if (hw::IsSessionRejection(verdict) && frame.command.session != last_rejected_session_) {
      last_rejected_session_ = frame.command.session;
      spdlog::warn("hw_emulator: command frames of link session {} rejected ({}; following {})",
                   frame.command.session, ToString(verdict), was);
    }
  } else {
    device_.OnRxError();
  }
}

void EmulatorNode::DiscardQueuedCommands() {
  // The firmware's rule after its loop stalled: the frames its receiver
  // queued meanwhile are not applied. Read now, each would look fresh (age is
  // judged on arrival) and drive the legs in turn with commands answering
  // samples taken before the stall; the next frame sent after it drives.
  const uint64_t behind_us = DeviceNow() - schedule_.next_tick_us();
  long discarded = 0;
  // Bounded: a flood while draining must not keep the loop from its samples.
  for (int reads = 0; reads < 100000 && Readable(link_->fd()); ++reads) {
    const long n = link_->Receive(rx_.data(), rx_.size(), 0);
    if (n < 0) break;
    if (n == 0) continue;  // a datagram from another peer (counted by the link)
    reader_.Feed(
        rx_.data(), static_cast<std::size_t>(n), rx_.size(),
        [&](const hw::DecodedFrame& f) { discarded += f.type == hw::FrameType::kCommand ? 1 : 0; },
        [&](hw::DecodeStatus) { device_.OnRxError(); });
  }
  stale_commands_discarded_ += discarded;
  spdlog::warn(
      "hw_emulator: loop stalled {} ms: {} command frame(s) queued meanwhile discarded ({} in all)",
      behind_us / 1000, discarded, stale_commands_discarded_);
}

ExitCode EmulatorNode::Run() {
  start_ = Clock::now();
  start_epoch_us_ = std::chrono::duration_cast<std::chrono::microseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
  const auto steady_at = [this](uint64_t device_us) {
    return start_ + std::chrono::microseconds(device_us - hw::SampleSchedule::kDeviceEpochUs);
  };
  while (!StopRequested()) {
    if (options_.duration_s > 0.0 &&
        Clock::now() - start_ > std::chrono::duration<double>(options_.duration_s)) {
      break;
    }
    if (schedule_.Due(DeviceNow())) {
      if (schedule_.Stalled(DeviceNow())) DiscardQueuedCommands();
      Tick(DeviceNow());
      continue;
    }
    if (!WaitReadable(link_->fd(), steady_at(schedule_.next_tick_us()))) continue;
    // Stopped while it waited: what is queued is the stall's (above).
    if (schedule_.Stalled(DeviceNow())) continue;
    const long n = link_->Receive(rx_.data(), rx_.size(), 0);
    if (n <= 0) continue;
    const uint64_t rx_us = DeviceNow();
    // A sample due before this arrival is taken first: the command acts
    // from its arrival on, never on the interval before the sample.
    while (schedule_.Due(rx_us)) Tick(rx_us);
    reader_.Feed(
        rx_.data(), static_cast<std::size_t>(n), rx_.size(),
        [&](const hw::DecodedFrame& f) { OnFrame(f, rx_us); },
        [&](hw::DecodeStatus) { device_.OnRxError(); });
  }
  if (!options_.pty_link.empty()) unlink(options_.pty_link.c_str());
  spdlog::info(
      "hw_emulator: stopped after {} samples ({} skipped while descheduled, {} command frames "
      "discarded after stalls)",
      schedule_.ticks(), schedule_.skipped(), stale_commands_discarded_);
  return ExitCode::kOk;
}

}  // namespace stewart
