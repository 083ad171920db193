#include "stewart/node/node_main.h"

#include <spdlog/spdlog.h>

#include <exception>
#include <memory>

#include "stewart/common/check.h"
#include "stewart/config/config_loader.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_options.h"
#include "stewart/node/operator_reset.h"
#include "stewart/node/stop_signal.h"

namespace stewart {

int NodeMain(int argc, char** argv, const NodeInfo& info, const AddFlagsFn& add_flags,
             const ApplyFlagsFn& apply_flags, const RunFn& run) {
  CLI::App app{info.description, info.name};
  NodeOptions options;
  AddNodeOptions(&app, &options);
  if (add_flags) add_flags(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0 through CLI11; a bad flag exits kBadInput.
    const int status = app.exit(e);
    return status == 0 ? ToInt(ExitCode::kOk) : ToInt(ExitCode::kBadInput);
  }
  StackConfig config;
  try {
    config = LoadNodeConfig(options);
    if (apply_flags) {
      if (const std::optional<ExitCode> early = apply_flags(config)) return ToInt(*early);
    }
    ValidateStackConfig(config);
  } catch (const InputError& e) {
    spdlog::error("{}: {} (config: {})", info.name, e.what(), options.config_path);
    return ToInt(ExitCode::kBadInput);
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}: {} (config: {})", info.name, e.what(), options.config_path);
    return ToInt(ExitCode::kBadInput);
  }
  PrepareForRealTimeIfScheduled(info.name);
  InstallStopSignalHandlers();
  try {
    std::unique_ptr<lcm::LCM> lcm;
    if (info.needs_lcm || !config.lcm.url.empty()) {
      lcm = MakeLcm(config.lcm.url);
      // Every heartbeat of this process takes the operator's RESETs from it.
      InstallOperatorResetListener(config.lcm);
    }
    return ToInt(run(config, lcm.get()));
  } catch (const InputError& e) {
    spdlog::error("{}: {}", info.name, e.what());
    return ToInt(ExitCode::kBadInput);
  } catch (const std::exception& e) {
    spdlog::error("{}: {}", info.name, e.what());
    return ToInt(ExitCode::kFault);
  }
}

}  // namespace stewart
