// safety_tool: reads {"q":[6],"qd":[6],"f_des":[6]} JSON lines on stdin and
// prints F* and the filter's diagnostics as one JSON line each: how a user
// finds out why the filter acted.
//   safety_tool [--config FILE] [--variant V] [--force-limits]
#include <CLI/CLI.hpp>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/safety/clp_reference_qp.h"
#include "stewart/safety/safety_filter.h"

namespace {

using nlohmann::json;
using stewart::Vector6d;

Vector6d ReadVector(const json& j, const char* key) {
  const json& a = j.at(key);
  if (!a.is_array() || a.size() != 6)
    throw std::invalid_argument(std::string(key) + ": need 6 numbers");
  Vector6d v;
  for (int i = 0; i < 6; ++i)
    v(i) =
        a.at(static_cast<size_t>(i)).is_null() ? NAN : a.at(static_cast<size_t>(i)).get<double>();
  return v;
}

json ToJson(const Vector6d& v) { return json(std::vector<double>(v.data(), v.data() + 6)); }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Run the CBF safety filter on (q, qd, f_des) JSON lines"};
  std::string config_path = stewart::DefaultConfigPath();
  std::string variant;
  bool force_limits = false;
  app.add_option("--config", config_path, "platform YAML");
  app.add_option("--variant", variant,
                 stewart::kSafetyVariantNames.Names() + " (default: from config)");
  app.add_flag("--force-limits", force_limits, "also enforce |F_i| <= actuators.force_limit_n");
  CLI11_PARSE(app, argc, argv);
  try {
    stewart::StackConfig config = stewart::LoadStackConfig(config_path);
    if (!variant.empty()) config.safety.variant = stewart::ParseSafetyVariant(variant);
    if (force_limits) config.safety.force_limits_enabled = true;
    stewart::safety::ClpReferenceQp clp;
    stewart::safety::SafetyFilter filter(config.platform, config.safety, config.actuators, &clp);
    const stewart::safety::ConstraintSet& c = filter.constraints();
    std::string line;
    while (std::getline(std::cin, line)) {
      if (line.empty()) continue;
      json out;
      try {
        const json in = json::parse(line);
        stewart::safety::SafetyDiagnostics d;
        const Vector6d f =
            filter.Step(ReadVector(in, "q"), ReadVector(in, "qd"), ReadVector(in, "f_des"), &d);
        const auto& b = d.barriers;
        out["f_safe"] = ToJson(f);
        out["variant"] = stewart::ToString(d.variant);
        out["correction_metric"] = stewart::ToString(filter.correction_metric());
        out["case"] = static_cast<int>(d.filter_case);
        out["infeasible"] = d.infeasible;
        out["flags"] = d.flags;
        for (size_t i = 0; i < static_cast<size_t>(c.num_position); ++i) {
          out["position"][c.position[i].name] = {
              {"h_D", b.h_position[i]}, {"alpha_h", b.alpha_h_position[i]}, {"w", b.w_position[i]}};
        }
        for (size_t i = 0; i < static_cast<size_t>(c.num_velocity); ++i) {
          out["velocity"][c.velocity[i].name] = {
              {"h_v", b.h_velocity[i]}, {"alpha_h", b.alpha_h_velocity[i]}, {"w", b.w_velocity[i]}};
        }
        out["h_pos"] = b.h_pos;
        out["h_vel"] = b.h_vel;
        out["psi_p"] = b.psi_p;
        out["psi_v"] = b.psi_v;
        out["g_p"] = ToJson(b.g_p);
        out["g_v"] = ToJson(b.g_v);
        out["mu_p"] = d.mu_p;
        out["mu_v"] = d.mu_v;
        out["mu_force"] = ToJson(d.mu_force);
        if (d.variant == stewart::SafetyVariant::kUncomposed) {
          // Each barrier's own multiplier; mu_p, mu_v above are their sums.
          for (size_t i = 0; i < static_cast<size_t>(c.num_position); ++i) {
            out["position"][c.position[i].name]["mu"] = d.mu_position[i];
          }
          for (size_t i = 0; i < static_cast<size_t>(c.num_velocity); ++i) {
            out["velocity"][c.velocity[i].name]["mu"] = d.mu_velocity[i];
          }
        }
        out["f_des"] = ToJson(d.f_des.allFinite() ? d.f_des : Vector6d::Zero());
        out["correction_norm"] = d.correction_norm;
        out["compute_ns"] = d.compute_ns;
      } catch (const std::exception& e) {
        out = {{"error", e.what()}};
      }
      std::cout << out.dump() << '\n';
    }
  } catch (const std::exception& e) {
    std::cerr << "safety_tool: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
