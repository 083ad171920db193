#pragma once
// A Monte-Carlo campaign (docs/campaign.md): N closed-loop runs in process,
// each with its own seed, scenario and truth drawn from a distribution file,
// with the estimator, controller and filter classes the processes run. A run
// is a function of (campaign, index) alone, so rows are identical in any
// shard and with any number of threads.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "stewart/config/stack_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/stack/campaign_distribution.h"
#include "stewart/stack/closed_loop.h"

namespace stewart {

struct CampaignSpec {
  std::string config_path;
  StackConfig config;
  YAML::Node config_root;
  /// "random" (drawn per run), a name of config/scenarios or a scenario file.
  std::string scenario = "paper";
  /// The scenario every run follows, loaded once; absent for "random".
  std::optional<Scenario> fixed_scenario;
  std::string distribution_path;  ///< empty: the exact model (truth = config)
  CampaignDistribution distribution;
  std::uint64_t seed = 1;
  double duration_s = 0.0;  ///< 0: the scenario's
  /// Random scenarios last this long (s) when duration_s is 0.
  double random_duration_s = 40.0;
  /// Ground truth to the controller and filter instead of the EKF (to tell
  /// the estimator's share of a failure from the rest's).
  bool perfect_state = false;
  /// Before each run, identify the truth's DC-motor legs in simulation
  /// (stewart_identify --mode actuators --plant sim) and run the stack with
  /// the identified actuators.motor overlay on `config`.
  bool identify_actuators = false;
};

/// Loads the config, the distribution (if any) and checks the scenario.
/// Throws ConfigError / InputError naming the file and key.
CampaignSpec MakeCampaignSpec(const std::string& config_path, const std::string& scenario,
                              const std::string& distribution_path, std::uint64_t seed,
                              double duration_s);

/// The seed of run `index`: a 32-bit mix of the campaign seed and the index
/// (it seeds the truth draw, the random scenario, sensor noise and pushes).
std::uint32_t RunSeed(std::uint64_t campaign_seed, long index);

/// Everything run `index` is made of.
struct RunSetup {
  long index = 0;
  std::uint32_t seed = 0;
  YAML::Node truth_yaml;  ///< the truth file of this run
  PlantTruth truth;
  std::vector<double> sampled;  ///< distribution.ColumnNames() order
  Scenario scenario{"", 0.0, {}};
  YAML::Node scenario_yaml;  ///< random scenarios only (Null otherwise)
  double duration_s = 0.0;
};
RunSetup SetUpRun(const CampaignSpec& spec, long index);

struct CampaignRow {
  long index = 0;
  std::uint32_t seed = 0;
  std::vector<double> sampled;
  ClosedLoopSummary summary;
  double wall_s = 0.0;
};

/// Runs `index`; `trajectory`, when not null, gets the per-tick CSV.
CampaignRow RunCampaignRow(const CampaignSpec& spec, long index, std::ostream* trajectory);

/// runs.csv: header and one line per row. Numbers are written with 17
/// significant digits so a row read back is the row computed.
std::vector<std::string> CampaignColumns(const CampaignSpec& spec);
std::string CampaignCsvHeader(const CampaignSpec& spec);  ///< the columns, comma-separated
std::string CampaignCsvLine(const CampaignSpec& spec, const CampaignRow& row);

/// The run indices of shard `shard` (1-based) of `shards`: every index i in
/// [0, runs) with i % shards == shard - 1. Throws InputError when shard is
/// not in [1, shards].
std::vector<long> ShardIndices(long runs, int shard, int shards);

/// Runs `indices` on `jobs` threads (each with its own copy of the spec);
/// returns the CSV lines in the order of `indices`. `progress(done)` is
/// called from the workers, serialised, after each run.
std::vector<std::string> RunCampaignLines(const CampaignSpec& spec,
                                          const std::vector<long>& indices, int jobs,
                                          const std::function<void(long done)>& progress);

/// A deep copy: yaml-cpp nodes share memory, so threads must not share them.
CampaignSpec CloneSpec(const CampaignSpec& spec);

/// The tolerance the campaign judges a limit by (m for positions, m/s for
/// rates): docs/safety.md, "Tolerance".
constexpr double kCampaignLimitTolerance = 1e-3;

}  // namespace stewart
