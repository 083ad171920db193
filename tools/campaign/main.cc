// stewart_campaign: Monte-Carlo runs of the whole control loop in process
// (no LCM) against plants drawn from a distribution file, and what they say
// (docs/campaign.md). Also merges shards, re-runs one row alone and writes
// the truth and launch line that reproduce it over LCM.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "stewart/common/check.h"
#include "stewart/config/config_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/stack/campaign.h"
#include "stewart/stack/campaign_summary.h"

namespace {

using nlohmann::json;
using namespace stewart;
namespace fs = std::filesystem;

constexpr int kExitOk = 0, kExitFault = 1, kExitBadInput = 2;

// One line on stderr, rewritten in place on a terminal, every 10 % otherwise.
class ProgressBar {
 public:
  explicit ProgressBar(long total)
      : total_(total), started_(std::chrono::steady_clock::now()), tty_(isatty(2) != 0) {}
  void Update(long done) {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - started_).count();
    const bool last = done == total_;
    if (tty_ ? (!last && elapsed - shown_s_ < 0.2) : (done * 10 / total_ == shown_tenth_ && !last))
      return;
    shown_s_ = elapsed;
    shown_tenth_ = done * 10 / total_;
    const double eta = done > 0 ? elapsed * static_cast<double>(total_ - done) / done : 0.0;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / total_);
    std::fprintf(stderr, "%s[%s%s] %ld/%ld runs, %.0f s elapsed, ETA %.0f s%s", tty_ ? "\r" : "",
                 std::string(static_cast<size_t>(filled), '#').c_str(),
                 std::string(static_cast<size_t>(kWidth - filled), '.').c_str(), done, total_,
                 elapsed, eta, tty_ && !last ? "" : "\n");
    std::fflush(stderr);
  }

 private:
  long total_;
  std::chrono::steady_clock::time_point started_;
  bool tty_;
  double shown_s_ = -1.0;
  long shown_tenth_ = -1;
};

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot write");
  out << text;
}

json Meta(const CampaignSpec& spec, long runs, const std::string& shard, int jobs) {
  return json{
      {"config", fs::absolute(spec.config_path).string()},
      {"scenario", spec.scenario},
      {"mismatch", spec.distribution_path.empty() ? std::string("none (exact model)")
                                                  : fs::absolute(spec.distribution_path).string()},
      {"seed", spec.seed},
      {"runs", runs},
      {"shard", shard},
      {"jobs", jobs},
      {"duration_s", spec.duration_s},
      {"perfect_state", spec.perfect_state},
      {"identify_actuators", spec.identify_actuators}};
}

// Summary files and plots of a folder holding runs.csv and campaign.json.
void Summarise(const std::string& dir, bool plots) {
  const CsvTable runs = ReadCsv(dir + "/runs.csv");
  const json meta = json::parse(ReadText(dir + "/campaign.json"));
  const json summary = SummarizeCampaign(runs, meta, kCampaignLimitTolerance);
  WriteText(dir + "/summary.json", summary.dump(2) + "\n");
  const std::string markdown = SummaryMarkdown(summary);
  WriteText(dir + "/summary.md", markdown);
  std::printf("%s", markdown.c_str());
  if (!plots) return;
  const std::string script = std::string(STEWART_SOURCE_DIR) + "/tools/plots/campaign_plots.py";
  const std::string command = "/usr/bin/python3 '" + script + "' '" + dir + "'";
  if (std::system(command.c_str()) != 0) {
    spdlog::warn("plots not written ({}): python3-matplotlib missing?", command);
  }
}

// Saves what a later --rerun needs: the settings, and the files by value.
void SaveCampaign(const std::string& dir, const CampaignSpec& spec, const json& meta) {
  fs::create_directories(dir);
  json saved = meta;
  saved["config_copy"] = "config.yaml";
  WriteText(dir + "/config.yaml", ReadText(spec.config_path));
  if (!spec.distribution_path.empty()) {
    WriteText(dir + "/mismatch.yaml", ReadText(spec.distribution_path));
    saved["mismatch_copy"] = "mismatch.yaml";
  }
  WriteText(dir + "/campaign.json", saved.dump(2) + "\n");
}

CampaignSpec LoadSavedSpec(const std::string& dir) {
  const json meta = json::parse(ReadText(dir + "/campaign.json"));
  const std::string mismatch =
      meta.contains("mismatch_copy") ? dir + "/" + meta["mismatch_copy"].get<std::string>() : "";
  CampaignSpec spec =
      MakeCampaignSpec(dir + "/config.yaml", meta["scenario"].get<std::string>(), mismatch,
                       meta["seed"].get<std::uint64_t>(), meta["duration_s"].get<double>());
  spec.perfect_state = meta.value("perfect_state", false);
  spec.identify_actuators = meta.value("identify_actuators", false);
  return spec;
}

int Run(const CampaignSpec& spec, long runs, int shard, int shards, int jobs,
        const std::string& out, bool plots) {
  const std::vector<long> indices = ShardIndices(runs, shard, shards);
  const std::string shard_text = std::to_string(shard) + "/" + std::to_string(shards);
  SaveCampaign(out, spec, Meta(spec, runs, shard_text, jobs));
  std::fprintf(
      stderr, "campaign: %zu runs of %s (shard %s), %d jobs, seed %llu, mismatch %s -> %s\n",
      indices.size(), spec.scenario.c_str(), shard_text.c_str(), jobs,
      static_cast<unsigned long long>(spec.seed),
      spec.distribution_path.empty() ? "none" : spec.distribution_path.c_str(), out.c_str());
  ProgressBar bar(static_cast<long>(indices.size()));
  const auto started = std::chrono::steady_clock::now();
  const std::vector<std::string> lines =
      RunCampaignLines(spec, indices, jobs, [&](long done) { bar.Update(done); });
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::ofstream csv(out + "/runs.csv");
  csv << CampaignCsvHeader(spec) << '\n';
  for (const std::string& line : lines) csv << line << '\n';
  csv.close();
  std::fprintf(stderr, "campaign: %zu runs in %.1f s wall\n", lines.size(), wall);
  Summarise(out, plots);
  return kExitOk;
}

int Merge(const std::vector<std::string>& dirs, const std::string& out, bool plots) {
  CsvTable merged;
  json meta;
  std::map<long, std::vector<std::string>> by_index;
  for (const std::string& dir : dirs) {
    const CsvTable t = ReadCsv(dir + "/runs.csv");
    if (merged.header.empty()) {
      merged.header = t.header;
      meta = json::parse(ReadText(dir + "/campaign.json"));
      fs::create_directories(out);
      for (const char* file : {"config.yaml", "mismatch.yaml"}) {
        if (fs::exists(dir + "/" + file) && fs::absolute(dir) != fs::absolute(out)) {
          fs::copy_file(dir + "/" + file, out + "/" + file, fs::copy_options::overwrite_existing);
        }
      }
    } else if (t.header != merged.header) {
      throw InputError(dir + "/runs.csv", "its columns differ from the first shard's");
    }
    const json other = json::parse(ReadText(dir + "/campaign.json"));
    for (const char* key : {"scenario", "seed", "mismatch", "runs"}) {
      if (other[key] != meta[key]) {
        throw InputError(dir + "/campaign.json",
                         std::string("'") + key + "' differs from the first shard's");
      }
    }
    const int index_col = t.Column("index");
    for (const auto& row : t.rows) {
      by_index[std::stol(row[static_cast<std::size_t>(index_col)])] = row;
    }
  }
  for (auto& [index, row] : by_index) merged.rows.push_back(row);
  meta["shard"] = "merged from " + std::to_string(dirs.size()) + " folders";
  WriteText(out + "/campaign.json", meta.dump(2) + "\n");
  WriteCsv(out + "/runs.csv", merged);
  spdlog::info("merge: {} runs from {} folders -> {}", merged.rows.size(), dirs.size(), out);
  if (static_cast<long>(merged.rows.size()) != meta["runs"].get<long>()) {
    spdlog::warn("merge: {} of the campaign's {} runs present", merged.rows.size(),
                 meta["runs"].get<long>());
  }
  Summarise(out, plots);
  return kExitOk;
}

int Rerun(const std::string& dir, long row_number, bool emit_truth) {
  const CsvTable runs = ReadCsv(dir + "/runs.csv");
  if (row_number < 0 || row_number >= static_cast<long>(runs.rows.size())) {
    throw InputError("--row", "must be 0 to " + std::to_string(runs.rows.size() - 1) +
                                  " (a data row of runs.csv, 0 = first)");
  }
  const std::vector<std::string>& stored = runs.rows[static_cast<std::size_t>(row_number)];
  const long index = std::stol(stored[static_cast<std::size_t>(runs.Column("index"))]);
  const CampaignSpec spec = LoadSavedSpec(dir);
  const std::string stem = dir + "/run_" + std::to_string(index);
  std::ofstream trajectory(stem + ".csv");
  trajectory.precision(17);  // every bit: comparable with the LCM run's log
  const CampaignRow row = RunCampaignRow(spec, index, &trajectory);
  const std::string line = CampaignCsvLine(spec, row);
  // Every field but the wall time must be what the campaign wrote.
  const CsvTable again = ParseCsv(CampaignCsvHeader(spec) + "\n" + line + "\n",
                                  "rerun of row " + std::to_string(row_number));
  const int wall_col = runs.Column("wall_s");
  bool same = again.header == runs.header;
  if (!same) spdlog::error("rerun: runs.csv has other columns (written by another version?)");
  for (std::size_t c = 0; same && c < stored.size(); ++c) {
    if (static_cast<int>(c) != wall_col && again.rows[0][c] != stored[c]) {
      spdlog::error("rerun: column {} is {} now, {} in runs.csv", runs.header[c], again.rows[0][c],
                    stored[c]);
      same = false;
    }
  }
  std::printf("run %ld (seed %u): trajectory %s.csv; %s\n%s", index, row.seed, stem.c_str(),
              same ? "identical to its row in runs.csv" : "DIFFERS from its row in runs.csv",
              FormatSummary(spec.config, row.summary).c_str());
  if (emit_truth) {
    const RunSetup setup = SetUpRun(spec, index);
    // A truth overrides the config file a plant is given, not its overlays
    // (docs/simulation.md, "Truth"): name the legs' model so that the file
    // gives the same plant with the base config and an overlay such as
    // config/overlays/p16p.yaml.
    YAML::Node truth_yaml = YAML::Clone(setup.truth_yaml);
    const YAML::Node& config_root = spec.config_root;
    if (config_root["actuators"]["model"] && !truth_yaml["actuators"]["model"]) {
      truth_yaml["actuators"]["model"] = config_root["actuators"]["model"].as<std::string>();
    }
    std::ostringstream truth;
    truth << "# The plant of campaign run " << index << " (seed " << setup.seed
          << "): plant_sim --truth / tools/launch.sh --truth\n"
          << truth_yaml << "\n";
    WriteText(stem + "_truth.yaml", truth.str());
    std::string scenario = spec.scenario;
    if (!setup.scenario_yaml.IsNull()) {
      std::ostringstream text;
      text << setup.scenario_yaml << "\n";
      scenario = stem + "_scenario.yaml";
      WriteText(scenario, text.str());
    }
    std::printf(
        "truth: %s_truth.yaml\nover LCM (lockstep, same seed):\n  tools/launch.sh --config %s "
        "--truth %s_truth.yaml --seed %u --scenario %s --duration %g --out %s_lcm\n",
        stem.c_str(), (dir + "/config.yaml").c_str(), stem.c_str(), setup.seed, scenario.c_str(),
        setup.duration_s, stem.c_str());
  }
  return same ? kExitOk : kExitFault;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "stewart_campaign: Monte-Carlo closed-loop runs (in process, no LCM) against plants "
      "drawn from a distribution file (docs/campaign.md)"};
  std::string config_path = DefaultConfigPath();
  std::string scenario = "paper", mismatch, out = "campaign", shard_text = "1/1", rerun_dir;
  long runs = 100, row = -1;
  std::uint64_t seed = 1;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  double duration_s = 0.0;
  bool no_plots = false, emit_truth = false, perfect_state = false, identify_actuators = false;
  std::string log_level = "error";
  std::vector<std::string> merge_dirs;
  app.add_option("--config", config_path, "stack YAML config (the model every run's stack uses)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  app.add_option("--runs", runs, "number of runs")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--scenario", scenario,
                 "paper | beyond-limits | circle | random | a scenario file")
      ->capture_default_str();
  app.add_option("--mismatch", mismatch,
                 "distribution of the plant's truth (config/campaigns/*.yaml); default: the "
                 "exact model")
      ->check(CLI::ExistingFile);
  app.add_option("--seed", seed, "campaign seed: run i's seed is a mix of it and i")
      ->capture_default_str();
  app.add_option("--jobs", jobs, "threads")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--shard", shard_text, "K/N: run only the indices i with i % N == K-1")
      ->capture_default_str();
  app.add_option("--duration", duration_s, "seconds per run (default: the scenario's)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--out", out, "output folder")->capture_default_str();
  app.add_flag("--no-plots", no_plots, "skip the matplotlib plots");
  app.add_flag("--identify-actuators", identify_actuators,
               "identify each run's DC-motor legs in simulation first (stewart_identify --mode "
               "actuators --plant sim) and run the stack with the identified motors");
  app.add_flag("--perfect-state", perfect_state,
               "ground truth to the controller and filter instead of the EKF");
  app.add_option("--log-level", log_level,
                 "what the runs' estimator, controller and filter log (their rejections are "
                 "counted in runs.csv either way)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  app.add_option("--merge", merge_dirs, "merge these shard folders into --out")->expected(1, -1);
  app.add_option("--rerun", rerun_dir, "a campaign folder: re-run one row (--row) alone");
  app.add_option("--row", row, "with --rerun: data row of runs.csv (0 = first)");
  app.add_flag("--emit-truth", emit_truth,
               "with --rerun: write the run's truth file and the launch line over LCM");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));
  try {
    if (!rerun_dir.empty()) {
      if (row < 0) throw InputError("--row", "is required with --rerun");
      return Rerun(rerun_dir, row, emit_truth);
    }
    if (!merge_dirs.empty()) return Merge(merge_dirs, out, !no_plots);
    int shard = 0, shards = 0;
    char slash = 0;
    std::istringstream shard_in(shard_text);
    if (!(shard_in >> shard >> slash >> shards) || slash != '/' || !shard_in.eof()) {
      throw InputError("--shard", "expected K/N, got '" + shard_text + "'");
    }
    CampaignSpec spec = MakeCampaignSpec(config_path, scenario, mismatch, seed, duration_s);
    spec.perfect_state = perfect_state;
    spec.identify_actuators = identify_actuators;
    if (identify_actuators && spec.config.actuators.kind != ActuatorKind::kDcMotor) {
      throw InputError("--identify-actuators",
                       "needs a config with actuators.model dc_motor (config/overlays/p16p.yaml)");
    }
    return Run(spec, runs, shard, shards, jobs, out, !no_plots);
  } catch (const InputError& e) {
    spdlog::error("stewart_campaign: {}", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    spdlog::error("stewart_campaign: {}", e.what());
    return kExitFault;
  }
}
