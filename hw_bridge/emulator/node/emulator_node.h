#pragma once
// The hw_emulator process's node: the device side of docs/wire-protocol.md
// over UDP or a pseudo-terminal, backed by plant_sim's plant and sensor
// models (PlantBackend) with the device watchdog (DeviceEmulator). With an
// LCM handle it also publishes the ground truth on lcm.channels.state_truth,
// as plant_sim does: for evaluation only (a real device has no ground truth;
// the stack never subscribes to it).
#include <array>
#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/hw_bridge/wire_format.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "stewart/hw_emulator/plant_backend.h"
#include "stewart/hw_emulator/sample_schedule.h"
#include "stewart/node/exit_code.h"

namespace stewart {

struct EmulatorOptions {
  std::string transport = "udp";  ///< "udp" | "pty"
  std::string pty_link;           ///< pty: a symlink to create to the slave device
  std::string bind_host;          ///< udp: "" = hw_bridge.device_host
  int device_port = -1;           ///< udp: < 0 = hw_bridge.device_port
  std::string host;               ///< udp: "" = hw_bridge.local_host
  int host_port = -1;             ///< udp: < 0 = hw_bridge.local_port
  double rate_hz = 0.0;           ///< sample rate; <= 0 = sensors.rate_hz
  double duration_s = 0.0;        ///< 0 = until a stop signal
  int drop_every = 0;             ///< drop every Nth sensor frame; 0 = none
  bool noise = true;
};

class EmulatorNode {
 public:
  /// `lcm` may be null: no ground truth. Throws InputError for a rate whose
  /// period rounds to zero.
  /// `truth`: the emulated platform's physics (TruthOfConfig for the config's own).
  EmulatorNode(const StackConfig& config, const PlantTruth& truth, lcm::LCM* lcm,
               const EmulatorOptions& options);

  /// Runs until the duration or a stop signal, then removes the pty link; kOk.
  ExitCode Run();

 private:
  using Clock = std::chrono::steady_clock;

  uint64_t DeviceNow() const;
  void Tick(uint64_t now_us);
  void OnFrame(const hw::DecodedFrame& frame, uint64_t rx_us);
  /// After a stall of its loop: the command frames queued meanwhile are read
  /// and dropped (counted), never applied.
  void DiscardQueuedCommands();

  const StackConfig& config_;
  lcm::LCM* lcm_;
  EmulatorOptions options_;
  std::unique_ptr<hw::PtyDevice> pty_;
  std::unique_ptr<hw::Transport> udp_;
  hw::Transport* link_ = nullptr;
  hw::PlantBackend backend_;
  hw::DeviceEmulator device_;
  hw::SampleSchedule schedule_;
  hw::FrameReader reader_;
  long stale_commands_discarded_ = 0;
  Clock::time_point start_;
  /// The host time base of hw_bridge (HostClock): the wall clock read once,
  /// advanced by the monotonic clock. Used only to stamp the ground truth.
  int64_t start_epoch_us_ = 0;
  std::array<uint8_t, 4096> rx_{};
  std::array<uint8_t, hw::kMaxFrameSize> tx_{};
  uint32_t last_rejected_session_ = 0;  // logged once per session, not per frame
};

/// The period of `rate_hz` in us; throws InputError naming --rate-hz when it
/// rounds to zero.
uint64_t EmulatorPeriodUs(double rate_hz);

}  // namespace stewart
