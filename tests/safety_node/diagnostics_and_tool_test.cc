// The safety filter's two user-facing outputs besides F*: the diagnostics
// message (FillDiagnosticsMessage, what lcm-spy and the logs show) and
// safety_tool (JSON lines in, F* and diagnostics out). Both must carry
// exactly what the library computed, so anyone can recheck a step.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "stewart/config/default_config.h"
#include "stewart/model/dynamics.h"
#include "stewart/safety/clp_reference_qp.h"
#include "stewart/safety/diagnostics_lcm.h"
#include "stewart/safety/safety_filter.h"

namespace stewart::safety {
namespace {

// A state near the z velocity limit moving up, with a nominal force that
// pushes further: the filter acts (velocity case).
struct Step {
  Vector6d q, qd, f_des;
};
Step ActiveStep() {
  Step s;
  s.q = DefaultStackConfig().home_pose;
  s.qd << 0.0, 0.0, 0.0095, 0.0, 0.0, 0.0;
  const DynamicsTerms t = EvaluateDynamics(DefaultStackConfig().platform, s.q, s.qd);
  Vector6d qdd;
  qdd << 0.0, 0.0, 2.0, 0.0, 0.0, 0.0;
  s.f_des = InverseDynamics(t, qdd);
  return s;
}

TEST(DiagnosticsMessage, CarriesEveryFilterQuantity) {
  SafetyFilter filter(DefaultStackConfig().platform, DefaultStackConfig().safety,
                      DefaultStackConfig().actuators);
  const Step s = ActiveStep();
  SafetyDiagnostics d;
  const Vector6d f = filter.Step(s.q, s.qd, s.f_des, &d);
  ASSERT_NE(d.filter_case, FilterCase::kNone);  // the step is interesting
  safety_diagnostics_t msg{};
  FillDiagnosticsMessage(filter, d, &msg);
  EXPECT_EQ(msg.variant, +safety_diagnostics_t::VARIANT_CLOSED_FORM);
  EXPECT_EQ(msg.correction_metric, +safety_diagnostics_t::METRIC_ACCELERATION);
  EXPECT_EQ(msg.active_case, static_cast<int8_t>(d.filter_case));
  EXPECT_EQ(msg.infeasible, d.infeasible);
  const ConstraintSet& c = filter.constraints();
  ASSERT_EQ(msg.num_position, c.num_position);
  ASSERT_EQ(msg.num_velocity, c.num_velocity);
  for (int i = 0; i < c.num_velocity; ++i) {
    const size_t k = static_cast<size_t>(i);
    EXPECT_EQ(msg.velocity_names[k], c.velocity[k].name);
    EXPECT_EQ(msg.h_velocity[k], d.barriers.h_velocity[k]);
    EXPECT_EQ(msg.alpha_h_velocity[k], d.barriers.alpha_h_velocity[k]);
    EXPECT_EQ(msg.w_velocity[k], d.barriers.w_velocity[k]);
  }
  for (int i = 0; i < c.num_position; ++i) {
    const size_t k = static_cast<size_t>(i);
    EXPECT_EQ(msg.position_names[k], c.position[k].name);
    EXPECT_EQ(msg.h_position[k], d.barriers.h_position[k]);
  }
  EXPECT_EQ(msg.h_vel, d.barriers.h_vel);
  EXPECT_EQ(msg.psi_v, d.barriers.psi_v);
  EXPECT_EQ(msg.psi_p, d.barriers.psi_p);
  EXPECT_EQ(msg.mu_p, d.mu_p);
  EXPECT_EQ(msg.mu_v, d.mu_v);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(msg.g_v[i], d.barriers.g_v(i));
    EXPECT_EQ(msg.g_p[i], d.barriers.g_p(i));
    EXPECT_EQ(msg.f_des[i], s.f_des(i));
    EXPECT_EQ(msg.f_nominal[i], d.f_nominal(i));
    EXPECT_EQ(msg.f_safe[i], f(i));
  }
  EXPECT_EQ(msg.correction_norm, d.correction_norm);
  EXPECT_EQ(msg.nominal_scale, d.nominal_scale);
  EXPECT_EQ(msg.compute_ns, d.compute_ns);
  // Recheck from the message alone plus the model: F* - F_nom is
  // W^-1 (mu_p g_p + mu_v g_v) in the acceleration metric.
  const DynamicsTerms t = EvaluateDynamics(DefaultStackConfig().platform, s.q, s.qd);
  const Matrix6d w = t.H.transpose() * t.M.inverse() * t.H;
  Vector6d g_p, g_v, f_des, f_safe;
  for (int i = 0; i < 6; ++i) {
    g_p(i) = msg.g_p[i];
    g_v(i) = msg.g_v[i];
    f_des(i) = msg.f_nominal[i];
    f_safe(i) = msg.f_safe[i];
  }
  const Vector6d predicted = f_des + w.inverse() * (msg.mu_p * g_p + msg.mu_v * g_v);
  EXPECT_LE((predicted - f_safe).norm(), 1e-9 * (1.0 + f_safe.norm()));
  // And the velocity condition holds at F* (with the robust margin).
  EXPECT_GE(msg.psi_v + g_v.dot(f_safe - f_des), -1e-12);
}

// Every metric has its own METRIC_* value (a reader recomputing F* needs it).
TEST(DiagnosticsMessage, NamesEveryCorrectionMetric) {
  EXPECT_EQ(ToLcmMetric(CorrectionMetric::kForce), +safety_diagnostics_t::METRIC_FORCE);
  EXPECT_EQ(ToLcmMetric(CorrectionMetric::kAcceleration),
            +safety_diagnostics_t::METRIC_ACCELERATION);
  EXPECT_EQ(ToLcmMetric(CorrectionMetric::kTaskAcceleration),
            +safety_diagnostics_t::METRIC_TASK_ACCELERATION);
}

TEST(DiagnosticsMessage, UncomposedCarriesEachBarriersMultiplier) {
  SafetyConfig config = DefaultStackConfig().safety;
  config.variant = SafetyVariant::kUncomposed;
  SafetyFilter filter(DefaultStackConfig().platform, config, DefaultStackConfig().actuators);
  const Step s = ActiveStep();
  SafetyDiagnostics d;
  filter.Step(s.q, s.qd, s.f_des, &d);
  ASSERT_GT(d.mu_v, 0.0);
  safety_diagnostics_t msg{};
  FillDiagnosticsMessage(filter, d, &msg);
  EXPECT_EQ(msg.variant, +safety_diagnostics_t::VARIANT_UNCOMPOSED);
  const ConstraintSet& c = filter.constraints();
  ASSERT_EQ(msg.mu_position.size(), static_cast<size_t>(c.num_position));
  ASSERT_EQ(msg.mu_velocity.size(), static_cast<size_t>(c.num_velocity));
  double sum_mu_v = 0.0;
  for (size_t k = 0; k < msg.mu_velocity.size(); ++k) {
    EXPECT_EQ(msg.mu_velocity[k], d.mu_velocity[k]);
    sum_mu_v += msg.mu_velocity[k];
  }
  for (size_t k = 0; k < msg.mu_position.size(); ++k) {
    EXPECT_EQ(msg.mu_position[k], d.mu_position[k]);
  }
  EXPECT_NEAR(sum_mu_v, msg.mu_v, 1e-12 * msg.mu_v);
  // It encodes: the arrays' sizes match their counts.
  std::vector<uint8_t> buffer(static_cast<size_t>(msg.getEncodedSize()));
  EXPECT_EQ(msg.encode(buffer.data(), 0, static_cast<int>(buffer.size())),
            static_cast<int>(buffer.size()));
}

TEST(DiagnosticsMessage, ComputeNsIsTheTimeOfTheFullStep) {
  // Step reads the clock once around the model terms and the filter;
  // StepWithTerms (terms given, e.g. the benches and tests) is not timed.
  SafetyFilter filter(DefaultStackConfig().platform, DefaultStackConfig().safety,
                      DefaultStackConfig().actuators);
  const Step s = ActiveStep();
  SafetyDiagnostics d;
  filter.Step(s.q, s.qd, s.f_des, &d);
  EXPECT_GT(d.compute_ns, 0);
  EXPECT_LT(d.compute_ns, 1000000000);
  const DynamicsTerms t = EvaluateDynamics(DefaultStackConfig().platform, s.q, s.qd);
  filter.StepWithTerms(t, s.q, s.qd, s.f_des, &d);
  EXPECT_EQ(d.compute_ns, 0);
}

std::string RunTool(const std::string& input, const std::string& args) {
  // One file per test and process: ctest runs the tests of this file in
  // parallel, and a shared name let one test read the other's input.
  const std::string in_path = ::testing::TempDir() + "safety_tool_in_" +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                              "_" + std::to_string(::getpid()) + ".jsonl";
  std::ofstream(in_path) << input;
  const std::string command =
      std::string(SAFETY_TOOL_PATH) + " " + args + " < " + in_path + " 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  std::string out;
  std::array<char, 4096> buffer{};
  while (pipe && std::fgets(buffer.data(), buffer.size(), pipe.get()) != nullptr) {
    out += buffer.data();
  }
  pipe.reset();
  std::remove(in_path.c_str());
  return out;
}

nlohmann::json Line(const Step& s) {
  auto vec = [](const Vector6d& v) { return std::vector<double>(v.data(), v.data() + 6); };
  return {{"q", vec(s.q)}, {"qd", vec(s.qd)}, {"f_des", vec(s.f_des)}};
}

TEST(SafetyTool, PrintsWhatTheLibraryComputesForEveryVariant) {
  const Step s = ActiveStep();
  for (const char* variant : {"closed_form", "paper", "qp", "uncomposed"}) {
    const std::string out = RunTool(Line(s).dump() + "\n", std::string("--variant ") + variant);
    const nlohmann::json j = nlohmann::json::parse(out);
    SafetyConfig config = DefaultStackConfig().safety;
    config.variant = ParseSafetyVariant(variant);
    ClpReferenceQp clp;
    SafetyFilter filter(DefaultStackConfig().platform, config, DefaultStackConfig().actuators,
                        &clp);
    SafetyDiagnostics d;
    const Vector6d f = filter.Step(s.q, s.qd, s.f_des, &d);
    EXPECT_EQ(j.at("variant"), variant);
    EXPECT_EQ(j.at("correction_metric"), "acceleration");
    EXPECT_EQ(j.at("case").get<int>(), static_cast<int>(d.filter_case)) << variant;
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(j.at("f_safe").at(static_cast<size_t>(i)).get<double>(), f(i),
                  1e-12 * (1.0 + std::fabs(f(i))))
          << variant;
    }
    EXPECT_NEAR(j.at("mu_v").get<double>(), d.mu_v, 1e-12 * (1.0 + d.mu_v));
    EXPECT_TRUE(j.at("velocity").contains("zd_upper"));
    if (config.variant == SafetyVariant::kUncomposed) {
      // Each barrier's own multiplier, summing to the group's.
      double sum_mu_v = 0.0;
      for (const auto& [name, barrier] : j.at("velocity").items()) {
        sum_mu_v += barrier.at("mu").get<double>();
      }
      EXPECT_NEAR(sum_mu_v, d.mu_v, 1e-12 * (1.0 + d.mu_v));
      EXPECT_GT(d.mu_v, 0.0);
    }
  }
}

TEST(SafetyTool, BadLinesGetAnErrorAndTheRestIsStillAnswered) {
  const Step s = ActiveStep();
  nlohmann::json nan_line = Line(s);
  nan_line["qd"][2] = nullptr;  // NaN in the input: flagged safe stop, finite output
  const std::string input = "not json\n" + std::string("{\"q\": [1, 2]}\n") + nan_line.dump() +
                            "\n" + Line(s).dump() + "\n";
  const std::string out = RunTool(input, "");
  std::vector<nlohmann::json> lines;
  size_t start = 0;
  while (start < out.size()) {
    const size_t end = out.find('\n', start);
    lines.push_back(nlohmann::json::parse(out.substr(start, end - start)));
    start = end + 1;
  }
  ASSERT_EQ(lines.size(), 4u) << out;
  EXPECT_TRUE(lines[0].contains("error"));
  EXPECT_TRUE(lines[1].contains("error"));
  EXPECT_EQ(lines[2].at("case").get<int>(), static_cast<int>(FilterCase::kFallback));
  for (const auto& v : lines[2].at("f_safe")) EXPECT_TRUE(std::isfinite(v.get<double>()));
  EXPECT_FALSE(lines[3].contains("error"));
}

}  // namespace
}  // namespace stewart::safety
