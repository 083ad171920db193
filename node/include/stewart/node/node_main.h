#pragma once
// The one shape of a process's main(). Every process of the stack
// (plant_sim, hw_bridge, hw_emulator, estimator, controller, safety) is
//
//   int main(int argc, char** argv) {
//     MyFlags flags;
//     return stewart::NodeMain(argc, argv, {"safety", "what it does"},
//         [&](CLI::App& app) { /* app.add_option(..., &flags.x) */ },
//         [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
//           /* apply flags to config; throw InputError */
//           return std::nullopt;
//         },
//         [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
//           MyNode node(config, lcm, flags);
//           return node.Run();  // ExitCode
//         });
//   }
//
// NodeMain owns what they share: the common flags (NodeOptions), one config
// load, the flag overrides, real-time preparation, stop signals, the LCM
// handle, the top-level exception handler and the exit status (ExitCode).
// The node itself is a thin class: it subscribes, converts messages to the
// library's types, calls the library's process class and publishes what it
// returns.
#include <CLI/CLI.hpp>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/node/exit_code.h"

namespace stewart {

struct NodeInfo {
  std::string name;         ///< the process name, as in logs and health_t.name
  std::string description;  ///< first line of --help
  /// False for a process that can run without an LCM handle (the emulator
  /// publishes only optional ground truth): `run` then gets nullptr when the
  /// URL is empty.
  bool needs_lcm = true;
};

using AddFlagsFn = std::function<void(CLI::App& app)>;
/// Applies the process's own flags to the loaded config. Throws InputError
/// (or ConfigError) for a bad value: NodeMain logs it and exits kBadInput.
/// Returns an exit code to end the process there (a flag that only prints),
/// std::nullopt to go on and run the node.
using ApplyFlagsFn = std::function<std::optional<ExitCode>(StackConfig& config)>;
using RunFn = std::function<ExitCode(const StackConfig& config, lcm::LCM* lcm)>;

int NodeMain(int argc, char** argv, const NodeInfo& info, const AddFlagsFn& add_flags,
             const ApplyFlagsFn& apply_flags, const RunFn& run);

}  // namespace stewart
