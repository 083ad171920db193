#include "operator_console.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <random>

#include "stewart/operator_command_t.hpp"
#include "stewart/safety/supervisor.h"

namespace stewart::viewer {

OperatorConsole::OperatorConsole(const StackConfig& config, lcm::LCM* lcm)
    : auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      lcm_(lcm),
      channel_(config.lcm.channels.operator_command) {
  std::random_device device;
  operator_id_ = std::uniform_int_distribution<int64_t>(1, INT64_MAX)(device);
}

void OperatorConsole::Send(const std::string& verb, const std::string& note) {
  const auto command = safety::kOperatorCommandNames.Find(verb);
  if (!command) throw InputError("command", "'" + verb + "' is not an operator command");
  const std::lock_guard<std::mutex> lock(mutex_);
  operator_command_t cmd{};
  // The operator's wall clock, as stewart_ctl sends it: the supervisor
  // checks it against its own (supervisor.operator_time_window_s).
  cmd.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
  cmd.seq = ++seq_;
  cmd.operator_id = operator_id_;
  cmd.command = static_cast<int8_t>(*command);
  cmd.note = note;
  auth_.Sign(&cmd);
  lcm_->publish(channel_, &cmd);
  spdlog::info("viewer: operator command '{}' sent (seq {})", verb, cmd.seq);
}

}  // namespace stewart::viewer
