#pragma once
// The live bus: a thread of its own receives the stack's channels and only
// stores the newest value of each (SnapshotStore), so it keeps up with the
// bus whatever the browsers do; frames are built from a copy elsewhere.
#include <atomic>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "message_samples.h"
#include "stewart/config/stack_config.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/viewer/frame_builder.h"
#include "stewart/viewer/snapshot_store.h"

namespace stewart::viewer {

class LiveSource {
 public:
  /// How often the receiving thread takes what the socket holds: well
  /// above the 60 Hz a browser is sent (docs/performance.md, "The viewer's cost").
  static constexpr std::chrono::milliseconds kDrainPeriod{5};

  LiveSource(const StackConfig& config, const FrameBuilder* builder);
  ~LiveSource();
  LiveSource(const LiveSource&) = delete;
  LiveSource& operator=(const LiveSource&) = delete;

  /// The next frame, or null when nothing arrived since the previous one.
  nlohmann::json NextFrame();
  /// Supervisor states dropped because their tag did not verify.
  int64_t forged_supervisor_states() const { return forged_; }

 private:
  void OnEstimate(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg);
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg);
  void OnSetpoint(const lcm::ReceiveBuffer*, const std::string&, const setpoint_t* msg);
  void OnNominal(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg);
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg);
  void OnDiagnostics(const lcm::ReceiveBuffer*, const std::string&,
                     const safety_diagnostics_t* msg);
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg);
  void OnSupervisor(const lcm::ReceiveBuffer*, const std::string&, const supervisor_state_t* msg);
  void OnOperator(const lcm::ReceiveBuffer*, const std::string&, const operator_command_t* msg);
  void Run();

  const FrameBuilder* builder_;
  MessageAuthenticator auth_;
  LcmReceiver receiver_;
  SnapshotStore store_;
  uint64_t sent_version_ = 0;
  std::atomic<int64_t> forged_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace stewart::viewer
