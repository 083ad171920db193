#include "live_source.h"

#include <spdlog/spdlog.h>

#include <chrono>

#include "message_samples.h"

namespace stewart::viewer {

LiveSource::LiveSource(const StackConfig& config, const FrameBuilder* builder)
    : builder_(builder),
      auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      receiver_(config.lcm.url) {
  const ChannelNames& ch = config.lcm.channels;
  receiver_.Subscribe(ch.state_estimate, &LiveSource::OnEstimate, this);
  receiver_.Subscribe(ch.state_truth, &LiveSource::OnTruth, this);
  receiver_.Subscribe(ch.setpoint, &LiveSource::OnSetpoint, this);
  receiver_.Subscribe(ch.command_nominal, &LiveSource::OnNominal, this);
  receiver_.Subscribe(ch.command_safe, &LiveSource::OnSafe, this);
  receiver_.Subscribe(ch.safety_diagnostics, &LiveSource::OnDiagnostics, this);
  receiver_.Subscribe(ch.health, &LiveSource::OnHealth, this);
  receiver_.Subscribe(ch.supervisor, &LiveSource::OnSupervisor, this);
  receiver_.Subscribe(ch.operator_command, &LiveSource::OnOperator, this);
  thread_ = std::thread([this] { Run(); });
}

LiveSource::~LiveSource() {
  stop_ = true;
  thread_.join();
}

void LiveSource::Run() {
  // Drained in batches, not woken per message: a task blocked on the socket
  // is woken by every loop message (~6 per sample at 1 kHz), on the
  // publisher's time, in the loop's hops. Sleeping between batches, the
  // viewer is never waiting when the loop publishes; the kernel buffer
  // (2 MiB requested, recv_buf_size) holds the few messages of one period.
  while (!stop_) {
    std::this_thread::sleep_for(kDrainPeriod);
    try {
      receiver_.HandleTimeout(0);
    } catch (const std::exception& e) {
      spdlog::error("viewer: receiving failed: {}", e.what());
    }
  }
}

void LiveSource::OnEstimate(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
  store_.Update([&](ViewerSnapshot& s) { s.estimate = ToSample(*msg); });
}
void LiveSource::OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
  store_.Update([&](ViewerSnapshot& s) { s.truth = ToSample(*msg); });
}
void LiveSource::OnSetpoint(const lcm::ReceiveBuffer*, const std::string&, const setpoint_t* msg) {
  store_.Update([&](ViewerSnapshot& s) { s.setpoint = ToSample(*msg); });
}
void LiveSource::OnNominal(const lcm::ReceiveBuffer*, const std::string&,
                           const force_command_t* msg) {
  store_.Update([&](ViewerSnapshot& s) { s.nominal = ToSample(*msg); });
}
void LiveSource::OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
  store_.Update([&](ViewerSnapshot& s) { s.safe = ToSample(*msg); });
}
void LiveSource::OnDiagnostics(const lcm::ReceiveBuffer*, const std::string&,
                               const safety_diagnostics_t* msg) {
  // Converted outside the lock: the barrier names are strings.
  DiagnosticsSample sample = ToSample(*msg);
  store_.Update([&](ViewerSnapshot& s) { s.diagnostics = std::move(sample); });
}
void LiveSource::OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
  HealthSample sample = ToSample(*msg);
  store_.Update([&](ViewerSnapshot& s) { s.health[sample.name] = std::move(sample); });
}
void LiveSource::OnSupervisor(const lcm::ReceiveBuffer*, const std::string&,
                              const supervisor_state_t* msg) {
  // The page must not show a state the actuators would not believe.
  if (!auth_.Verify(*msg)) {
    ++forged_;
    return;
  }
  store_.Update([&](ViewerSnapshot& s) { s.supervisor = ToSample(*msg); });
}

void LiveSource::OnOperator(const lcm::ReceiveBuffer*, const std::string&,
                            const operator_command_t* msg) {
  // Shown whether or not it verifies, marked: a forged command on the bus is
  // worth seeing (the supervisor refuses it).
  OperatorSample sample = ToSample(*msg, auth_.Verify(*msg));
  store_.Update([&](ViewerSnapshot& s) { s.last_operator_command = std::move(sample); });
}

nlohmann::json LiveSource::NextFrame() {
  uint64_t version = 0;
  const ViewerSnapshot snapshot = store_.Copy(&version);
  if (version == sent_version_) return nullptr;
  sent_version_ = version;
  nlohmann::json frame = builder_->Frame(snapshot);
  frame["mode"] = "live";
  return frame;
}

}  // namespace stewart::viewer
