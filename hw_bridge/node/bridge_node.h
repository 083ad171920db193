#pragma once
// The hw_bridge process's node: sensor frames from the device -> sensor_t on
// channels.sensors (as plant_sim publishes them), force_command_t from
// channels.command_safe -> command frames (docs/wire-protocol.md). In
// bring-up mode (hw_bridge --bringup, hw_bridge/bringup.h) duty_command_t
// from <prefix>BRINGUP_DUTY instead, and the device's applied duty echoed on
// <prefix>BRINGUP_DUTY_APPLIED per sample. What to do with each frame,
// command and silence is hw::HwBridge's; this class only moves bytes and
// messages, verifies their MACs (node/message_auth.h) and reports the
// heartbeat. It also hears the safety session's announcements
// (supervisor_state_t) and the operator's RESET (operator_command_t), which
// clears the bridge's tripped guard.
#include <array>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/duty_command_t.hpp"
#include "stewart/force_command_t.hpp"
#include "stewart/guard/operator_command_check.h"
#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_bridge/host_clock.h"
#include "stewart/hw_bridge/transport.h"
#include "stewart/hw_bridge/wire_format.h"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/message_auth.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {

class BridgeNode {
 public:
  BridgeNode(const StackConfig& config, lcm::LCM* lcm, hw::Transport* transport,
             const hw::BringupOptions& bringup = {});

  /// Runs until a stop signal; kOk.
  ExitCode Run();

 private:
  void ReadDevice();
  void OnFrame(const hw::DecodedFrame& frame);
  void OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                 const force_command_t* msg);
  void OnDutyCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                     const duty_command_t* msg);
  void OnSupervisor(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                    const supervisor_state_t* msg);
  void OnOperator(const lcm::ReceiveBuffer* rbuf, const std::string& channel,
                  const operator_command_t* msg);
  void PublishApplied();
  void SendCommand();
  void UpdateHealth();

  const StackConfig& config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  hw::Transport* transport_;
  hw::HwBridge bridge_;
  MessageAuthenticator auth_;
  OperatorCommandCheck operator_check_;
  int64_t guard_trips_logged_ = 0;
  HealthReporter health_;
  hw::HostClock clock_;
  hw::FrameReader reader_;
  std::array<uint8_t, 4096> rx_{};
  std::string applied_channel_;  // bring-up only
  int64_t applied_seq_ = 0;
};

}  // namespace stewart
