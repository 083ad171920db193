#include "stewart/stack/campaign.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

#include "stewart/config/config_loader.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/identify/simulated_identification.h"
#include "stewart/stack/campaign_summary.h"
#include "stewart/stack/random_scenario.h"

namespace stewart {
namespace {

// The stack's config with the actuators identified on this run's plant.
StackConfig IdentifiedConfig(const CampaignSpec& spec, const PlantTruth& truth,
                             std::uint32_t seed) {
  const std::string overlay = identify::IdentifyActuatorsInSimulation(
      spec.config, truth, "stewart_campaign run seed " + std::to_string(seed));
  YAML::Node merged = YAML::Clone(spec.config_root);
  ApplyConfigOverlay(YAML::Load(overlay), "identified actuators", &merged);
  std::stringstream text;
  text << merged;
  return ParseStackConfig(text.str());
}

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

std::string Number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

}  // namespace

std::uint32_t RunSeed(std::uint64_t campaign_seed, long index) {
  return static_cast<std::uint32_t>(
      SplitMix64(SplitMix64(campaign_seed) ^ static_cast<std::uint64_t>(index)) >> 32);
}

CampaignSpec MakeCampaignSpec(const std::string& config_path, const std::string& scenario,
                              const std::string& distribution_path, std::uint64_t seed,
                              double duration_s) {
  CampaignSpec spec;
  spec.config_path = config_path;
  spec.config = LoadStackConfig(config_path);
  spec.config_root = LoadYamlFile(config_path);
  spec.scenario = scenario;
  if (scenario != "random") spec.fixed_scenario = LoadScenario(ResolveScenarioPath(scenario));
  spec.distribution_path = distribution_path;
  if (!distribution_path.empty()) {
    spec.distribution = ParseDistribution(LoadYamlFile(distribution_path), spec.config_root);
  }
  spec.seed = seed;
  if (!(duration_s >= 0.0)) throw InputError("--duration", "must not be negative");
  spec.duration_s = duration_s;
  // One draw now, so a distribution whose truths do not parse fails here,
  // naming the key, rather than in every run.
  SetUpRun(spec, 0);
  return spec;
}

RunSetup SetUpRun(const CampaignSpec& spec, long index) {
  RunSetup run;
  run.index = index;
  run.seed = RunSeed(spec.seed, index);
  std::mt19937_64 rng(run.seed);
  SampledTruth sampled = spec.distribution.parameters.empty()
                             ? SampledTruth{YAML::Node(YAML::NodeType::Map), {}}
                             : SampleTruth(spec.distribution, &rng);
  run.truth_yaml = sampled.truth;
  run.sampled = std::move(sampled.values);
  if (spec.scenario == "random") {
    // The random setpoints span the run, however long it is.
    const double length_s = spec.duration_s > 0.0 ? spec.duration_s : spec.random_duration_s;
    const RandomRun random = MakeRandomRun(spec.config, length_s, &rng);
    run.scenario = random.scenario;
    run.scenario_yaml = random.scenario_yaml;
    YAML::Node pose(YAML::NodeType::Sequence), velocity(YAML::NodeType::Sequence);
    for (int a = 0; a < 6; ++a) {
      pose.push_back(random.initial_pose(a));
      velocity.push_back(random.initial_velocity(a));
    }
    pose.SetStyle(YAML::EmitterStyle::Flow);
    velocity.SetStyle(YAML::EmitterStyle::Flow);
    run.truth_yaml["initial_state"]["pose"] = pose;
    run.truth_yaml["initial_state"]["velocity"] = velocity;
  } else {
    run.scenario = *spec.fixed_scenario;
  }
  run.truth = ParsePlantTruth(spec.config, spec.config_root, run.truth_yaml);
  run.duration_s = spec.duration_s > 0.0 ? spec.duration_s : run.scenario.duration_s();
  return run;
}

CampaignRow RunCampaignRow(const CampaignSpec& spec, long index, std::ostream* trajectory) {
  const auto started = std::chrono::steady_clock::now();
  RunSetup run;
  try {
    run = SetUpRun(spec, index);
  } catch (const std::exception& e) {
    // A truth the distribution can draw but the plant cannot take: a failed
    // row, reported, not a stopped campaign.
    CampaignRow row;
    row.index = index;
    row.seed = RunSeed(spec.seed, index);
    row.sampled.assign(spec.distribution.ColumnNames().size(),
                       std::numeric_limits<double>::quiet_NaN());
    for (std::string& name : LimitNames(spec.config.safety)) {
      row.summary.limit_margins.push_back({name, std::numeric_limits<double>::quiet_NaN()});
    }
    row.summary.failure = std::string("setup: ") + e.what();
    return row;
  }
  ClosedLoopOptions options;
  options.duration_s = run.duration_s;
  options.seed = run.seed;
  options.truth = run.truth;
  options.perfect_state = spec.perfect_state;
  CampaignRow row;
  row.index = index;
  row.seed = run.seed;
  row.sampled = run.sampled;
  if (spec.identify_actuators) {
    StackConfig identified;
    try {
      identified = IdentifiedConfig(spec, run.truth, run.seed);
    } catch (const std::exception& e) {
      row.summary.failure = std::string("actuator identification: ") + e.what();
      for (std::string& name : LimitNames(spec.config.safety)) {
        row.summary.limit_margins.push_back({name, std::numeric_limits<double>::quiet_NaN()});
      }
      return row;
    }
    row.summary = RunClosedLoop(identified, run.scenario, options, trajectory);
  } else {
    row.summary = RunClosedLoop(spec.config, run.scenario, options, trajectory);
  }
  row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return row;
}

std::vector<long> ShardIndices(long runs, int shard, int shards) {
  if (shards < 1 || shard < 1 || shard > shards) {
    throw InputError("--shard", "must be K/N with 1 <= K <= N, got " + std::to_string(shard) + "/" +
                                    std::to_string(shards));
  }
  std::vector<long> indices;
  for (long i = shard - 1; i < runs; i += shards) indices.push_back(i);
  return indices;
}

CampaignSpec CloneSpec(const CampaignSpec& spec) {
  CampaignSpec copy = spec;
  copy.config_root = YAML::Clone(spec.config_root);
  for (ParameterSpec& p : copy.distribution.parameters) p.fixed = YAML::Clone(p.fixed);
  return copy;
}

std::vector<std::string> RunCampaignLines(const CampaignSpec& spec,
                                          const std::vector<long>& indices, int jobs,
                                          const std::function<void(long done)>& progress) {
  if (jobs < 1) throw InputError("--jobs", "must be at least 1");
  std::vector<std::string> lines(indices.size());
  std::atomic<std::size_t> next{0};
  std::mutex mutex;  // guards the spec copies and progress
  long done = 0;
  auto work = [&] {
    CampaignSpec local;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      local = CloneSpec(spec);
    }
    for (std::size_t i = next++; i < indices.size(); i = next++) {
      lines[i] = CampaignCsvLine(local, RunCampaignRow(local, indices[i], nullptr));
      const std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (progress) progress(done);
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  return lines;
}

std::vector<std::string> CampaignColumns(const CampaignSpec& spec) {
  std::vector<std::string> columns = {"index", "seed", "scenario"};
  for (const std::string& name : spec.distribution.ColumnNames()) columns.push_back(name);
  const std::vector<std::string> limits = LimitNames(spec.config.safety);
  for (const std::string& name : limits) columns.push_back(name + "_excess");
  for (const std::string& name : limits) columns.push_back(name + "_margin");
  for (const char* name :
       {"tracking_rms_m", "estimate_rms_m", "estimate_rms_mps", "estimator_restarts",
        "estimator_rejections", "fallback_ticks", "infeasible_ticks", "nominal_bounded_ticks",
        "per_barrier_ticks", "endstop_hits", "leg_stroke_margin_m", "stiff_fallbacks", "armed_s",
        "completed", "failure", "wall_s"}) {
    columns.push_back(name);
  }
  return columns;
}

std::string CampaignCsvHeader(const CampaignSpec& spec) {
  std::string header;
  for (const std::string& column : CampaignColumns(spec)) {
    header += (header.empty() ? "" : ",") + column;
  }
  return header;
}

std::string CampaignCsvLine(const CampaignSpec& spec, const CampaignRow& row) {
  const ClosedLoopSummary& s = row.summary;
  std::ostringstream line;
  line << row.index << ',' << row.seed << ',' << CsvField(spec.scenario);
  for (const double v : row.sampled) line << ',' << Number(v);
  for (const LimitMargin& m : s.limit_margins) line << ',' << Number(m.excess());
  for (const LimitMargin& m : s.limit_margins) line << ',' << Number(m.worst_margin);
  line << ',' << Number(s.rms_translation_tracking_inside_m) << ',' << Number(s.rms_q_error) << ','
       << Number(s.rms_qd_error) << ',' << s.estimator_reinits << ',' << s.estimator_rejections
       << ',' << s.fallback_ticks << ',' << s.infeasible_ticks << ',' << s.nominal_bounded_ticks
       << ',' << s.per_barrier_ticks << ',' << s.endstop_hits << ','
       << Number(s.leg_stroke_worst_margin_m) << ',' << s.stiff_fallbacks << ','
       << Number(s.armed_s) << ',' << (s.completed ? 1 : 0) << ',' << CsvField(s.failure) << ','
       << Number(row.wall_s);
  return line.str();
}

}  // namespace stewart
