#pragma once
// The safety process: state estimate + nominal command in, safe command and
// diagnostics out, one per nominal command. All timing from message utimes.
#include <array>
#include <lcm/lcm-cpp.hpp>
#include <memory>

#include "stewart/config/stack_config.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/exit_code.h"
#include "stewart/node/health_reporter.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/safety/safety_filter.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {

class SafetyNode {
 public:
  SafetyNode(const StackConfig& config, lcm::LCM* lcm, safety::ReferenceQpSolver* reference);

  /// Handles LCM traffic until a stop signal. Returns the exit status.
  ExitCode Run();

  void OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg);
  void OnNominal(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg);

 private:
  const state_t* FindState(int64_t sample_utime) const;
  void Publish(const state_t& state, int64_t sample_utime, const Vector6d& force_n,
               const safety::SafetyDiagnostics& diagnostics, int32_t extra_flags);
  void PublishFallback(const state_t& state, int32_t reason_flag);
  void FilterNominal(const state_t& state, const force_command_t& nominal);

  const StackConfig& config_;
  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  safety::SafetyFilter filter_;
  HealthReporter health_;
  const int64_t stale_age_us_;

  // The states the next nominal commands can refer to (a command derives
  // from one state estimate, matched by sample_utime).
  static constexpr int kStateHistory = 64;
  std::array<state_t, kStateHistory> states_{};
  int states_count_ = 0;
  int states_next_ = 0;
  int64_t newest_state_utime_ = -1;
  int64_t newest_nominal_sample_utime_ = -1;
  int64_t last_published_sample_utime_ = -1;
  // A nominal command that arrived before its state (see OnNominal).
  force_command_t pending_nominal_{};
  bool has_pending_nominal_ = false;

  int64_t seq_ = 0;
  force_command_t command_{};
  safety_diagnostics_t diagnostics_msg_{};
  safety::SafetyDiagnostics diagnostics_{};
};

}  // namespace stewart
