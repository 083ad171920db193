// stewart_config_merge: a config with overlays applied, checked and written
// as one file (tools/launch.sh --overlay writes the run folder's config.yaml
// with it, so replay and the report read what ran).
//
//   stewart_config_merge --config config/platform.yaml --overlay identified.yaml --out
//   run/config.yaml
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <fstream>

#include "stewart/config/config_loader.h"
#include "stewart/node/exit_code.h"

int main(int argc, char** argv) {
  CLI::App app{"Apply YAML overlays to the stack config, validate, and write the merged config"};
  std::string config_path = stewart::DefaultConfigPath(), out_path;
  std::vector<std::string> overlays;
  app.add_option("-c,--config", config_path, "YAML config")->capture_default_str();
  app.add_option("--overlay", overlays, "overlay file (repeatable, applied in order)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("-o,--out", out_path, "merged config file to write")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    // Parsing validates the merged document as every process will load it.
    stewart::LoadStackConfig(config_path, overlays);
    YAML::Emitter yaml;
    yaml << stewart::LoadMergedConfigYaml(config_path, overlays);
    std::ofstream out(out_path);
    out << "# " << config_path << " with overlays applied in order (stewart_config_merge):\n";
    for (const std::string& overlay : overlays) out << "#   " << overlay << '\n';
    out << yaml.c_str() << '\n';
    if (!out) {
      spdlog::error("cannot write '{}'", out_path);
      return stewart::ToInt(stewart::ExitCode::kBadInput);
    }
  } catch (const stewart::ConfigError& e) {
    spdlog::error("{}", e.what());
    return stewart::ToInt(stewart::ExitCode::kBadInput);
  }
  return 0;
}
