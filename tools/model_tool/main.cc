// stewart_model_tool: evaluate the platform model and print JSON.
//
//   stewart_model_tool --q 0 0 0.4 0 0 0 --qd 0 0 0.01 0 0 0 --F 3 3 3 3 3 3
//   echo '{"q":[0,0,0.45,0,0,0.1],"l":[0.45,0.45,0.45,0.45,0.45,0.45]}' |
//     stewart_model_tool --stdin
#include <CLI/CLI.hpp>
#include <iostream>
#include <string>
#include <vector>

#include "model_json.h"
#include "stewart/config/config_loader.h"

int main(int argc, char** argv) {
  CLI::App app{
      "Evaluate the Stewart platform model (IK, FK, J_l, M, C qd, G, H, "
      "forward and inverse dynamics) and print JSON"};
  std::string config_path = stewart::DefaultConfigPath();
  std::vector<double> q, qd, force, qdd, legs;
  bool from_stdin = false;
  int indent = -1;
  app.add_option("-c,--config", config_path, "YAML config")->capture_default_str();
  app.add_option("--q", q, "pose x y z phi theta psi (m, rad); default: home pose")->expected(6);
  app.add_option("--qd", qd, "velocity (m/s, rad/s)")->expected(6);
  app.add_option("--F", force, "leg forces for forward dynamics (N)")->expected(6);
  app.add_option("--qdd", qdd, "acceleration for inverse dynamics")->expected(6);
  app.add_option("--l", legs, "leg lengths for forward kinematics (m), from --q as guess")
      ->expected(6);
  app.add_flag("--stdin", from_stdin,
               "read one JSON object per line {q, qd, F, qdd, l}; print one per line");
  app.add_option("--indent", indent, "pretty-print with this indent");
  CLI11_PARSE(app, argc, argv);

  stewart::StackConfig config;
  try {
    config = stewart::LoadStackConfig(config_path);
  } catch (const stewart::ConfigError& e) {
    std::cerr << e.what() << " (file: " << config_path << ")\n";
    return 2;
  }

  auto run = [&](const nlohmann::json& in) {
    const stewart::ModelQuery query = stewart::ParseModelQuery(in, config.home_pose);
    std::cout << stewart::EvaluateModelQuery(config.platform, query, &config.actuators).dump(indent)
              << "\n";
  };

  if (!from_stdin) {
    nlohmann::json in = nlohmann::json::object();
    if (!q.empty()) in["q"] = q;
    if (!qd.empty()) in["qd"] = qd;
    if (!force.empty()) in["F"] = force;
    if (!qdd.empty()) in["qdd"] = qdd;
    if (!legs.empty()) in["l"] = legs;
    try {
      run(in);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  int status = 0;
  std::string line;
  for (int line_no = 1; std::getline(std::cin, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      run(nlohmann::json::parse(line));
    } catch (const std::exception& e) {
      std::cout << nlohmann::json{{"error", e.what()}, {"line", line_no}}.dump() << "\n";
      status = 1;
    }
  }
  return status;
}
