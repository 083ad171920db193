// The Monte-Carlo campaign (docs/campaign.md): a row is a function of the
// campaign and its index alone (any shard, any number of threads), the
// summary reads what the rows say, and bad distribution files are named.
#include "stewart/stack/campaign.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/safety/constraint_set.h"
#include "stewart/stack/campaign_summary.h"
#include "stewart/stack/random_scenario.h"

namespace stewart {
namespace {

const std::string kBounds = std::string(STEWART_SOURCE_DIR) + "/config/campaigns/bounds.yaml";

// Short runs keep the test fast; 1.5 s covers the estimator's settling and
// a setpoint step.
CampaignSpec Spec(const std::string& scenario, const std::string& mismatch) {
  return MakeCampaignSpec(DefaultConfigPath(), scenario, mismatch, 7, 1.5);
}

// Every field but the last (wall time).
std::string WithoutWallTime(const std::string& line) { return line.substr(0, line.rfind(',')); }

TEST(Campaign, RowsAreTheSameWithAnyJobsAndShards) {
  CampaignSpec spec = Spec("random", kBounds);
  spec.random_duration_s = 1.5;
  const std::vector<long> all = ShardIndices(6, 1, 1);
  const std::vector<std::string> one_job = RunCampaignLines(spec, all, 1, nullptr);
  const std::vector<std::string> two_jobs = RunCampaignLines(spec, all, 2, nullptr);
  ASSERT_EQ(one_job.size(), 6u);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(WithoutWallTime(one_job[i]), WithoutWallTime(two_jobs[i])) << "run " << i;
  }
  // Shards 1/2 and 2/2 hold the even and odd indices, with the same rows.
  for (int shard = 1; shard <= 2; ++shard) {
    const std::vector<long> indices = ShardIndices(6, shard, 2);
    ASSERT_EQ(indices.size(), 3u);
    const std::vector<std::string> lines = RunCampaignLines(spec, indices, 1, nullptr);
    for (std::size_t k = 0; k < indices.size(); ++k) {
      EXPECT_EQ(indices[k] % 2, shard - 1);
      EXPECT_EQ(WithoutWallTime(lines[k]),
                WithoutWallTime(one_job[static_cast<std::size_t>(indices[k])]));
    }
  }
  // Different runs drew different plants.
  EXPECT_NE(WithoutWallTime(one_job[0]), WithoutWallTime(one_job[1]));
}

// The random scenario starts inside the safe set the filter keeps: its
// position limits are the configured ones drawn in by the joints'
// tolerance, so a start 5 mm inside a configured limit can be outside them;
// and its energy barriers leave less room for speed where the legs' rotors
// are heavy (the P-16P overlay).
void ExpectRandomStartsInsideTheSafeSet(const std::string& config_path) {
  const CampaignSpec spec = MakeCampaignSpec(config_path, "random", "", 1, 0.0);
  const SafetyConfig& safety = spec.config.safety;
  const safety::ConstraintSet constraints =
      safety::BuildConstraintSet(spec.config.platform, safety);
  const Vector6d margin = constraints.joint_tolerance_margin;
  ASSERT_GT(margin(0), 0.005) << "a tolerance narrower than the start's room tests nothing";
  for (long index = 0; index < 1000; ++index) {
    const RunSetup run = SetUpRun(spec, index);
    Vector6d q, qd;
    for (int a = 0; a < 6; ++a) {
      q(a) = run.truth_yaml["initial_state"]["pose"][a].as<double>();
      qd(a) = run.truth_yaml["initial_state"]["velocity"][a].as<double>();
    }
    for (const PositionLimitConfig& l : safety.position_limits) {
      if (l.upper) {
        EXPECT_LE(q(l.axis), *l.upper - margin(l.axis) - 0.005) << "run " << index;
      }
      if (l.lower) {
        EXPECT_GE(q(l.axis), *l.lower + margin(l.axis) + 0.005) << "run " << index;
      }
    }
    for (const VelocityLimitConfig& l : safety.velocity_limits) {
      if (l.upper) {
        EXPECT_LE(qd(l.axis), 0.5 * *l.upper) << "run " << index;
      }
      if (l.lower) {
        EXPECT_GE(qd(l.axis), 0.5 * *l.lower) << "run " << index;
      }
    }
    EXPECT_TRUE(InsideSafeSet(spec.config.platform, constraints, q, qd)) << "run " << index;
  }
}

// The shipped config with the P-16P overlay, as a file (removed with the
// object).
struct P16pConfigFile {
  std::string path =
      testing::TempDir() + "/campaign_test_p16p_" + std::to_string(::getpid()) + ".yaml";
  P16pConfigFile() {
    std::ofstream(path) << LoadMergedConfigYaml(DefaultConfigPath(), {DcMotorOverlayPath()});
  }
  ~P16pConfigFile() { std::remove(path.c_str()); }
};

TEST(Campaign, RandomStartsAreInsideTheSafeSet) {
  ExpectRandomStartsInsideTheSafeSet(DefaultConfigPath());
  const P16pConfigFile p16p;
  ExpectRandomStartsInsideTheSafeSet(p16p.path);
}

// 1 mm inside the filter's x limit, moving along x at half its velocity
// limit: inside with the ideal legs (kinetic energy ~3e-5 J against
// alpha_e h = 1e-3 J), outside with the P-16P rotors in M; at rest inside
// with both; beyond the limit or too fast outside with both.
TEST(Campaign, InsideSafeSetWeighsTheKineticEnergy) {
  const P16pConfigFile p16p;
  for (const std::string& path : {DefaultConfigPath(), p16p.path}) {
    const StackConfig config = LoadStackConfig(path);
    const safety::ConstraintSet constraints =
        safety::BuildConstraintSet(config.platform, config.safety);
    ASSERT_EQ(config.safety.position_limits[0].axis, 0);
    const double x_limit_m =
        *config.safety.position_limits[0].upper - constraints.joint_tolerance_margin(0);
    Vector6d q = config.home_pose;
    q(0) = x_limit_m - 0.001;
    Vector6d qd = Vector6d::Zero();
    EXPECT_TRUE(InsideSafeSet(config.platform, constraints, q, qd)) << path;
    qd(0) = 0.0075;
    EXPECT_EQ(InsideSafeSet(config.platform, constraints, q, qd), path == DefaultConfigPath())
        << path;
    qd(0) = 0.0;
    qd(2) = 0.011;  // above the z velocity limit (0.010 m/s)
    EXPECT_FALSE(InsideSafeSet(config.platform, constraints, config.home_pose, qd)) << path;
    q(0) = x_limit_m + 0.0001;
    EXPECT_FALSE(InsideSafeSet(config.platform, constraints, q, Vector6d::Zero())) << path;
  }
}

TEST(Campaign, ShardMustBeInRange) {
  EXPECT_THROW(ShardIndices(10, 0, 2), InputError);
  EXPECT_THROW(ShardIndices(10, 3, 2), InputError);
}

TEST(Campaign, SampledValuesReachTheTruth) {
  const CampaignSpec spec = Spec("paper", kBounds);
  const RunSetup run = SetUpRun(spec, 3);
  const std::vector<std::string> names = spec.distribution.ColumnNames();
  ASSERT_EQ(names.size(), run.sampled.size());
  const auto value = [&](const std::string& name) {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return run.sampled[i];
    ADD_FAILURE() << "no column " << name;
    return 0.0;
  };
  EXPECT_EQ(run.truth.payload.mass_kg, value("platform.payload.mass_kg"));
  EXPECT_EQ(run.truth.actuator_errors.force_gain(2), value("actuators.force_gain[2]"));
  EXPECT_DOUBLE_EQ(run.truth.latency.command_s, 1e-3 * value("latency.command_ms"));
  const double scale = value("platform.mass_kg");  // a scale: the mass is config x scale
  EXPECT_GE(scale, 0.8 * spec.config.platform.platform_mass_kg);
  EXPECT_LE(scale, 1.5 * spec.config.platform.platform_mass_kg);
  EXPECT_DOUBLE_EQ(run.truth.platform.platform_mass_kg, scale + run.truth.payload.mass_kg);
  EXPECT_GT(run.truth.disturbance.random_pushes.max_force_n, 0.0);
}

// The exact model, a short paper run: every limit held on ground truth, and
// the summary counts what the rows hold.
TEST(Campaign, ExactModelHoldsAndSummaryAgreesWithTheRows) {
  const CampaignSpec spec = Spec("paper", "");
  const std::vector<std::string> lines = RunCampaignLines(spec, ShardIndices(2, 1, 1), 2, nullptr);
  const std::string dir =
      testing::TempDir() + "/campaign_summary_test_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  {
    std::ofstream csv(dir + "/runs.csv");
    csv << CampaignCsvHeader(spec) << '\n';
    for (const std::string& l : lines) csv << l << '\n';
  }
  const CsvTable table = ReadCsv(dir + "/runs.csv");
  ASSERT_EQ(table.rows.size(), 2u);
  const nlohmann::json s = SummarizeCampaign(table, {{"scenario", "paper"}}, 1e-3);
  EXPECT_EQ(s["runs"], 2);
  EXPECT_EQ(s["runs_held"], 2);
  EXPECT_EQ(s["failed_runs"].size(), 0u);
  EXPECT_GT(s["worst_position_margin_m"]["min"].get<double>(), 0.0);
  for (const auto& limit : s["limits"]) EXPECT_EQ(limit["runs_beyond_tolerance"], 0);
  // The supervisor armed in both (auto-arm after its start-up checks): the
  // motion clock ran for most of the 1.5 s.
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    EXPECT_GT(table.Number(r, table.Column("armed_s")), 1.0) << "row " << r;
  }
  EXPECT_EQ(s["runs_never_armed"].size(), 0u);
  // A row edited to exceed x by 2 mm is counted, and named.
  CsvTable edited = table;
  edited.rows[1][static_cast<std::size_t>(edited.Column("x_upper_excess"))] = "0.002";
  const nlohmann::json e = SummarizeCampaign(edited, {}, 1e-3);
  EXPECT_EQ(e["runs_held"], 1);
  EXPECT_EQ(e["limits"][0]["limit"], "x_upper");
  EXPECT_EQ(e["limits"][0]["runs_beyond_tolerance"], 1);
  EXPECT_EQ(e["limits"][0]["worst_run"]["index"], 1);
  // A row whose supervisor never armed is named in the health section.
  edited.rows[0][static_cast<std::size_t>(edited.Column("armed_s"))] = "0";
  const nlohmann::json a = SummarizeCampaign(edited, {}, 1e-3);
  ASSERT_EQ(a["runs_never_armed"].size(), 1u);
  EXPECT_EQ(a["runs_never_armed"][0]["index"], 0);
  EXPECT_NE(SummaryMarkdown(a).find("supervisor never armed (no usable estimate, or a start "
                                    "outside a limit nothing steers back from; the drive stayed "
                                    "off): 1 (index 0)"),
            std::string::npos)
      << SummaryMarkdown(a);
  std::filesystem::remove_all(dir);
}

struct BadDistribution {
  const char* yaml;
  const char* key;
};

class CampaignRejects : public ::testing::TestWithParam<BadDistribution> {};

TEST_P(CampaignRejects, NamingTheKey) {
  // One file per parameter: ctest runs the instances in parallel.
  const std::string path =
      testing::TempDir() + "/bad_distribution_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream out(path);
    out << GetParam().yaml;
  }
  try {
    Spec("paper", path);
    FAIL() << "accepted: " << GetParam().yaml;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(GetParam().key), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CampaignRejects,
    ::testing::Values(
        BadDistribution{"parameters: [{key: controller.kp, uniform: [0, 1]}]",
                        "campaign.parameters[0].key"},
        BadDistribution{"parameters: [{key: platform.mass_kg}]", "campaign.parameters[0].key"},
        BadDistribution{"parameters: [{key: platform.mass_kg, uniform: [2, 1]}]",
                        "campaign.parameters[0].uniform"},
        BadDistribution{"parameters: [{key: platform.mass_kg, normal: [1, -1]}]",
                        "campaign.parameters[0].normal"},
        BadDistribution{"parameters: [{key: platform.mass_kg, uniform: [1]}]",
                        "campaign.parameters[0].uniform"},
        BadDistribution{"parameters: [{key: platform.payload.mass_kg, scale_uniform: [1, 2]}]",
                        "campaign.parameters[0].key"},
        BadDistribution{"parameters: [{key: actuators.force_gain, size: 9, uniform: [1, 2]}]",
                        "campaign.parameters[0].size"},
        // Drawn values the truth cannot take: the truth's key is named.
        BadDistribution{"parameters: [{key: platform.mass_kg, uniform: [-2, -1]}]",
                        "truth.platform.mass_kg"},
        BadDistribution{"parameters: [{key: platform.wheels, uniform: [1, 2]}]",
                        "truth.platform.wheels"},
        BadDistribution{"parameters: 3", "campaign.parameters"}));

}  // namespace
}  // namespace stewart

namespace stewart {
namespace {

// Run 7 of the bounds campaign on the paper scenario (seed 1) drives a leg
// into end-stop chatter that stalls the explicit integrator (ARKODE gave up
// with ARK_ERR_FAILURE before the fallback existed); the plant integrates
// those intervals with BDF and the run completes.
// A truth within the bounds runs its whole scenario: whatever the stack does
// with it, the plant's integrator survives (end-stop chatter falls back to
// the implicit method: PlantEndStop.ChatterFallsBackToTheStiffIntegrator).
TEST(Campaign, BoundsRunCompletes) {
  const CampaignSpec spec = MakeCampaignSpec(DefaultConfigPath(), "paper", kBounds, 1, 0.0);
  const CampaignRow row = RunCampaignRow(spec, 7, nullptr);
  EXPECT_TRUE(row.summary.completed) << row.summary.failure;
  EXPECT_EQ(row.summary.ticks, 40000);
}

// With the exact model (sensor noise on), the random scenario's runs of
// campaign seed 1 that once broke a limit beyond the 1 mm, 1 mm/s tolerance:
// 6, 23, 24, 53, 59, 72, 95, 123, 138 through the composed condition's
// trade between nearly active barriers (up to 40 mm/s in xd), 127 and 129
// through a leg reaching its end stop and an estimator restart. Each barrier
// checked (safety.check_each_barrier) and the leg-stroke barriers hold them
// all (docs/safety.md, "Each barrier checked"). Run 59 drew its start
// 3 mm inside the filter's x limit, before starts kept 5 mm inside it
// (docs/campaign.md, "Random starts inside the filter's limits"): it runs
// from that start here, the rest of the run as the campaign draws it.
ClosedLoopSummary RunFromStart(const CampaignSpec& spec, long index, const Vector6d& pose,
                               const Vector6d& velocity) {
  const RunSetup run = SetUpRun(spec, index);
  ClosedLoopOptions options;
  options.duration_s = run.duration_s;
  options.seed = run.seed;
  options.truth = run.truth;
  options.truth->initial_pose = pose;
  options.truth->initial_velocity = velocity;
  return RunClosedLoop(spec.config, run.scenario, options, nullptr);
}

TEST(Campaign, ExactModelRandomRunsThatOnceBrokeALimitHold) {
  const CampaignSpec spec = MakeCampaignSpec(DefaultConfigPath(), "random", "", 1, 0.0);
  Vector6d pose_59, velocity_59;
  pose_59 << 0.10047874906307575, 0.083726760217120361, 0.46541845547404032, 0.064566053172701268,
      0.00037344108612659356, 0.045602607721660464;
  velocity_59 << -0.0042426381779905589, 0.00014597704659844278, -0.00025369932825717147, 0.0, 0.0,
      0.0;
  for (const int index : {6, 23, 24, 53, 59, 72, 95, 123, 127, 129, 138}) {
    const ClosedLoopSummary s = index == 59 ? RunFromStart(spec, index, pose_59, velocity_59)
                                            : RunCampaignRow(spec, index, nullptr).summary;
    EXPECT_TRUE(s.completed) << "run " << index << ": " << s.failure;
    EXPECT_EQ(s.estimator_reinits, 0) << "run " << index;
    EXPECT_EQ(s.endstop_hits, 0) << "run " << index;
    for (const LimitMargin& m : s.limit_margins) {
      EXPECT_LE(m.excess(), 1e-3) << "run " << index << ": " << m.name;
    }
  }
}

}  // namespace
}  // namespace stewart

namespace stewart {
namespace {

// The summary ranks the sampled parameters by how they move the worst
// margins: a parameter the margin follows exactly correlates +1, one it
// follows backwards -1.
TEST(CampaignSummary, RanksTheParametersThatMoveTheMargin) {
  CsvTable t;
  t.header = {"index",           "seed",           "scenario",           "p_follows",
              "p_against",       "x_upper_excess", "x_upper_margin",     "xd_upper_excess",
              "xd_upper_margin", "completed",      "estimator_restarts", "wall_s"};
  const double follows[] = {0.1, 0.5, 0.2, 0.9, 0.4};
  for (int r = 0; r < 5; ++r) {
    const double margin = 0.01 * follows[r] - 0.002;
    t.rows.push_back({std::to_string(r), "1", "paper", std::to_string(follows[r]),
                      std::to_string(-follows[r]), std::to_string(std::max(0.0, -margin)),
                      std::to_string(margin), "0", std::to_string(0.001 + 0.0001 * r), "1", "0",
                      "0.1"});
  }
  const nlohmann::json s = SummarizeCampaign(t, {}, 1e-3);
  ASSERT_EQ(s["parameters"].size(), 2u);
  EXPECT_EQ(s["parameters"][0]["parameter"], "p_follows");
  EXPECT_NEAR(s["parameters"][0]["rank_correlation_position"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(s["parameters"][1]["rank_correlation_position"].get<double>(), -1.0, 1e-12);
  EXPECT_NE(SummaryMarkdown(s).find("| p_follows | +1.00 |"), std::string::npos)
      << SummaryMarkdown(s);
}

}  // namespace
}  // namespace stewart

namespace stewart {
namespace {

// --perfect-state: the controller and the filter get ground truth, so no
// estimator settles (no fallback at the start) and nothing is estimated.
TEST(Campaign, PerfectStateBypassesTheEstimator) {
  CampaignSpec spec = Spec("paper", kBounds);
  const CampaignRow with_ekf = RunCampaignRow(spec, 2, nullptr);
  spec.perfect_state = true;
  const CampaignRow perfect = RunCampaignRow(spec, 2, nullptr);
  EXPECT_GT(with_ekf.summary.fallback_ticks, 0);
  EXPECT_GT(with_ekf.summary.rms_q_error, 0.0);
  EXPECT_EQ(perfect.summary.fallback_ticks, 0);
  EXPECT_EQ(perfect.summary.rms_q_error, 0.0);
  EXPECT_EQ(perfect.summary.estimator_reinits, 0);
}

}  // namespace
}  // namespace stewart
