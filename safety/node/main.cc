// safety: the CBF safety filter as a process (docs/safety.md).
#include <spdlog/spdlog.h>

#include "safety_node.h"
#include "stewart/node/node_main.h"
#include "stewart/safety/clp_reference_qp.h"

int main(int argc, char** argv) {
  std::string variant;
  bool force_limits = false;
  int64_t lose_seq = -1;
  return stewart::NodeMain(
      argc, argv,
      {"safety", "CBF safety filter: STATE_EST + CMD_NOMINAL -> CMD_SAFE + SAFETY_DIAG"},
      [&](CLI::App& app) {
        app.add_option("--variant", variant,
                       stewart::kSafetyVariantNames.Names() + " (default: safety.variant)");
        app.add_flag("--force-limits", force_limits,
                     "also enforce |F_i| <= actuators.force_limit_n");
        app.add_option("--test-lose-seq", lose_seq,
                       "do not publish the safe command with this seq, once, as if the network "
                       "lost it (testing only)");
      },
      [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
        if (!variant.empty()) {
          config.safety.variant = stewart::kSafetyVariantNames.Parse(variant, "--variant");
        }
        if (force_limits) config.safety.force_limits_enabled = true;
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        stewart::safety::ClpReferenceQp reference;
        stewart::SafetyNode node(config, lcm, &reference);
        if (lose_seq >= 0) node.LoseCommandForTest(lose_seq);
        spdlog::info("safety: variant {}, {} -> {} on {}",
                     stewart::kSafetyVariantNames.Name(config.safety.variant),
                     config.lcm.channels.command_nominal, config.lcm.channels.command_safe,
                     config.lcm.url);
        const stewart::Vector6d& margin =
            node.process().filter().constraints().joint_tolerance_margin;
        if (margin.head<3>().maxCoeff() > 0.0) {
          spdlog::info(
              "safety: the joints' tolerance draws the position limits in by x {:.1f}, y {:.1f}, "
              "z {:.1f} mm",
              1e3 * margin(0), 1e3 * margin(1), 1e3 * margin(2));
        }
        return node.Run();
      });
}
