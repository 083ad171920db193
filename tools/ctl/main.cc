// stewart_ctl: the operator's console to the supervisor (docs/operations.md,
// "Arming and e-stop").
//
//   stewart_ctl arm|hold|resume|estop|reset   send one command, wait for the
//                                             supervisor's answer, print the state
//   stewart_ctl status                        print the supervisor's state
//   stewart_ctl heartbeat                     a dead-man console: heartbeats until
//                                             stopped (supervisor.operator_timeout_s)
//
// Exit status: 0 when the command was accepted (status: a state was heard),
// 1 when no supervisor answered, 2 for a bad argument, 5 when the supervisor
// refused the command (its reason on stderr).
#include <spdlog/spdlog.h>

#include <chrono>
#include <iostream>
#include <random>

#include "stewart/node/message_auth.h"
#include "stewart/node/node_main.h"
#include "stewart/node/stop_signal.h"
#include "stewart/node/supervisor_listener.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/safety/supervisor.h"
#include "stewart/supervisor_state_t.hpp"

namespace stewart {
namespace {

int64_t WallUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

const char* StateName(int8_t state) {
  if (state < 0 || state > static_cast<int8_t>(safety::SupervisorState::kEstop)) return "UNKNOWN";
  return safety::ToString(static_cast<safety::SupervisorState>(state));
}

void PrintState(const supervisor_state_t& s) {
  std::cout << StateName(s.state) << std::endl;
  std::cerr << "  reason: " << s.reason << (s.fault_latched ? " (fault latched: reset)" : "")
            << "\n  motion time: " << static_cast<double>(s.motion_time_us) * 1e-6 << " s, arming "
            << s.arming_progress << ", session " << std::hex << s.session_id << std::dec << "\n";
}

}  // namespace
}  // namespace stewart

int main(int argc, char** argv) {
  using stewart::operator_command_t;
  std::string verb;
  double timeout_s = 2.0;
  double period_s = 0.2;
  std::string note;
  return stewart::NodeMain(
      argc, argv,
      {"stewart_ctl", "operator console: arm | hold | resume | estop | reset | status | heartbeat"},
      [&](CLI::App& app) {
        app.add_option("command", verb, "arm, hold, resume, estop, reset, status or heartbeat")
            ->required()
            ->check(
                CLI::IsMember({"arm", "hold", "resume", "estop", "reset", "status", "heartbeat"}));
        app.add_option("--timeout", timeout_s, "seconds to wait for the supervisor (default 2)")
            ->check(CLI::PositiveNumber);
        app.add_option("--period", period_s, "heartbeat: seconds between heartbeats (default 0.2)")
            ->check(CLI::PositiveNumber);
        app.add_option("--note", note, "free text logged with the command");
      },
      [&](stewart::StackConfig&) -> std::optional<stewart::ExitCode> { return std::nullopt; },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) -> stewart::ExitCode {
        stewart::MessageAuthenticator auth =
            stewart::MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file);
        const std::string& channel = config.lcm.channels.supervisor;
        stewart::SupervisorListener listener(config.lcm.url, channel, &auth);
        if (verb == "status") {
          if (!listener.WaitFor(
                  timeout_s, [](const auto&) { return true; }, stewart::StopRequested)) {
            spdlog::error(
                "no supervisor state on {} within {} s (is the safety process running on {}?){}",
                channel, timeout_s, config.lcm.url,
                listener.forged() > 0 ? " (states with a bad MAC were dropped)" : "");
            return stewart::ExitCode::kFault;
          }
          stewart::PrintState(listener.matched());
          return stewart::ExitCode::kOk;
        }
        std::random_device device;
        operator_command_t cmd{};
        cmd.operator_id = std::uniform_int_distribution<int64_t>(1, INT64_MAX)(device);
        cmd.note = note;
        const auto command = *stewart::safety::kOperatorCommandNames.Find(verb);
        cmd.command = static_cast<int8_t>(command);
        auto send = [&] {
          cmd.utime = stewart::WallUs();
          ++cmd.seq;
          auth.Sign(&cmd);
          lcm->publish(config.lcm.channels.operator_command, &cmd);
        };
        if (verb == "heartbeat") {
          spdlog::info("stewart_ctl: heartbeats on {} every {} s until stopped",
                       config.lcm.channels.operator_command, period_s);
          while (!stewart::StopRequested()) {
            send();
            listener.WaitFor(
                period_s, [](const auto&) { return false; }, stewart::StopRequested);
          }
          return stewart::ExitCode::kOk;
        }
        send();
        const auto is_reply = [&](const stewart::supervisor_state_t& s) {
          return s.last_operator_id == cmd.operator_id && s.last_operator_seq == cmd.seq;
        };
        if (!listener.WaitFor(timeout_s, is_reply, stewart::StopRequested)) {
          spdlog::error(
              "no answer to '{}' on {} within {} s (is the safety process running on {}?){}", verb,
              channel, timeout_s, config.lcm.url,
              config.lcm.auth_key_file.empty() ? "" : " (a supervisor with another key drops it)");
          return stewart::ExitCode::kFault;
        }
        const stewart::supervisor_state_t& reply = listener.matched();
        if (!reply.last_operator_reply.empty()) {
          std::cerr << "refused: " << reply.last_operator_reply << "\n";
          stewart::PrintState(reply);
          return stewart::ExitCode::kRefused;
        }
        stewart::PrintState(reply);
        return stewart::ExitCode::kOk;
      });
}
