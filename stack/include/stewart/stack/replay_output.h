#pragma once
// The replay's results as a human-readable summary, as JSON (--json) and the
// filter's steps as CSV (--csv). docs/operations.md, "Replay".
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "stewart/stack/replay.h"

namespace stewart::replay {

struct ReplayReport {
  std::string run_dir;
  std::string log_path;
  std::string config_path;
  std::string scenario_path;   ///< "" unless the controller was replayed
  std::string variant_source;  ///< where the variant came from: --variant, run.yaml or config
  const RecordedLog* log = nullptr;
  std::optional<SafetyReplayResult> safety;
  std::optional<ControllerReplayResult> controller;
  std::optional<EstimatorReplayResult> estimator;

  /// Number of replayed outputs (of every replay run) that differ from the
  /// recorded ones, and of those compared.
  long Differing() const;
  long Compared() const;
  /// Of Differing(), those at or after the log's first publisher restart.
  long DifferingAfterRestart() const;
};

nlohmann::ordered_json ToJson(const ReplayReport& report);
std::string FormatSummary(const ReplayReport& report);
/// One row per safe command the replayed process published: sample_utime,
/// kind, flags, case, times, replayed and recorded forces (17 significant
/// digits: exact doubles).
void WriteSafetyStepsCsv(const SafetyReplayResult& safety, std::ostream& out);

}  // namespace stewart::replay
