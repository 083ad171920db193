#pragma once
// Offline replay of a run recorded by tools/launch.sh: the safety filter, the
// controller and the estimator re-run on the recorded inputs (read with
// lcm::LogFile, no network) and their outputs compared with what the live
// processes published. docs/operations.md, "Replay".
//
// Each replay mirrors its node: messages are matched by sample_utime as the
// node matches them, the node's status checks and fallbacks are applied the
// same way, and the library is the one the node links, so on the same build
// the replayed outputs are bit-identical to the recorded ones.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "stewart/common/enum_table.h"
#include "stewart/config/stack_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/force_command_t.hpp"
#include "stewart/safety/reference_qp.h"
#include "stewart/safety/two_constraint_qp.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart::replay {

/// Unusable input (missing or unreadable log, no messages to replay, ...):
/// the tool reports it and exits 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The part of a recorded safety_diagnostics_t the replay needs.
struct RecordedDiagnostics {
  int64_t sample_utime = 0;
  int64_t compute_ns = 0;
  int8_t variant = 0;  ///< safety_diagnostics_t::VARIANT_*
  bool force_limits = false;
};

enum class Channel {
  kSensors,
  kStateEstimate,
  kStateTruth,
  kCommandNominal,
  kCommandSafe,
  kSafetyDiagnostics,
};
constexpr int kNumChannels = 6;

/// Messages of one channel missing from the log, from gaps in `seq` (which
/// increments by one per message): lcm-logger drops bursts when it is
/// descheduled (docs/operations.md, Troubleshooting), the live stack did not.
struct SeqGaps {
  long missing = 0;  ///< messages
  long gaps = 0;     ///< bursts
  /// utime of the last message before the first gap (the first message's
  /// utime - 1 when the log lacks the first ones); -1 without gaps.
  int64_t intact_until_utime = -1;
};

/// The stack's messages of one log, decoded, each channel in log order.
struct RecordedLog {
  std::vector<sensor_t> sensors;
  std::vector<state_t> estimates;
  std::vector<state_t> truth;
  std::vector<force_command_t> nominal;
  std::vector<force_command_t> safe;
  std::vector<RecordedDiagnostics> diagnostics;
  /// Every decoded message above in log order: its channel and its index in
  /// that channel's vector (the estimator interleaves sensors and commands).
  std::vector<std::pair<Channel, int>> order;
  std::array<std::string, kNumChannels> channel_names;  ///< by Channel
  std::array<SeqGaps, kNumChannels> gaps;               ///< by Channel
  long events = 0;                                      ///< every event of the log
  std::map<std::string, long> undecodable;              ///< per stack channel
  int64_t first_timestamp_us = 0;                       ///< logger receive times (wall clock)
  int64_t last_timestamp_us = 0;
  int64_t first_utime = -1;  ///< stack time span of the decoded messages (us)
  int64_t last_utime = -1;
};

/// Reads every event of `path`, decoding the messages on `channels`. Throws
/// InputError when the file cannot be opened or holds no LCM event.
RecordedLog ReadLog(const std::string& path, const ChannelNames& channels);

/// Replayed against recorded values of one output.
struct DiffStats {
  long compared = 0;
  long identical = 0;  ///< every value bit-identical and the other fields equal
  double max_abs_diff = 0.0;
  /// Per step max_i |d_i| / max_i |recorded_i| (0 where both are 0).
  double max_rel_diff = 0.0;
  int64_t worst_sample_utime = -1;  ///< where max_abs_diff was reached

  long differing() const { return compared - identical; }
  void Add(int64_t sample_utime, const double* replayed, const double* recorded, int n,
           bool other_fields_equal);
};

/// Per-step times (ns): numpy's default (linear) percentiles.
struct TimeStats {
  long count = 0;
  double p50_ns = 0.0;
  double p99_ns = 0.0;
  double max_ns = 0.0;
};
TimeStats ComputeTimeStats(std::vector<int64_t> ns);

// ---------------------------------------------------------------------------
// Safety filter

/// How the recorded safe command for one replayed nominal command was made.
enum class SafetyStepKind {
  kCompared,    ///< by the filter: compared with the replay
  kFallback,    ///< the live node answered with a fallback (FLAG_FALLBACK / FLAG_STALE_INPUT)
  kUnrecorded,  ///< no recorded safe command with this sample_utime
};
inline constexpr EnumTable<SafetyStepKind, 3> kSafetyStepKindNames{{{
    {SafetyStepKind::kCompared, "compared"},
    {SafetyStepKind::kFallback, "fallback"},
    {SafetyStepKind::kUnrecorded, "unrecorded"},
}}};

/// One replayed filter step (one recorded nominal command with its state).
struct SafetyStep {
  int64_t sample_utime = 0;
  SafetyStepKind kind = SafetyStepKind::kCompared;
  std::array<double, 6> f_replayed{};
  std::array<double, 6> f_recorded{};  ///< zero for kUnrecorded
  int32_t replayed_flags = 0;
  int32_t recorded_flags = 0;
  int8_t replayed_case = 0;  ///< safety_diagnostics_t::CASE_*
  int64_t replayed_ns = 0;   ///< SafetyDiagnostics::compute_ns
  int64_t recorded_ns = -1;  ///< recorded safety_diagnostics_t.compute_ns, -1 if absent
};

struct SafetyReplayResult {
  SafetyVariant variant = SafetyVariant::kClosedForm;
  std::string qp_solver;  ///< name of the reference solver for variant qp, else ""
  bool force_limits = false;
  double k_position = 0.0;
  double k_velocity = 0.0;
  /// The variant / force limits of the live filter (most frequent in the
  /// recorded diagnostics), if any diagnostics were recorded.
  std::optional<SafetyVariant> recorded_variant;
  std::optional<bool> recorded_force_limits;

  long nominal_commands = 0;          ///< recorded nominal commands
  long without_state = 0;             ///< no recorded estimate with their sample_utime
  long without_recorded_command = 0;  ///< no recorded safe command with their sample_utime
  long answered_by_fallback = 0;      ///< the recorded safe command is a fallback
  DiffStats filter;                   ///< the filter's commands: replay vs recorded
  long flags_differ = 0;              ///< among them, force_command_t.flags differ

  /// Every recorded fallback command (FLAG_FALLBACK or FLAG_STALE_INPUT),
  /// whether or not a nominal command exists for it, by the path the node took.
  long fallback_commands = 0;
  long fallback_stale_input = 0;    ///< node watchdog / stale nominal (FLAG_STALE_INPUT)
  long fallback_invalid_state = 0;  ///< node: state not valid (estimator initialising, diverged)
  long fallback_by_filter = 0;      ///< the filter's own last resort (infeasible, invalid F_des)
  long fallback_without_input = 0;  ///< no recorded state (or nominal) to replay it from
  DiffStats fallback;               ///< replayed safe stop / filter vs recorded

  TimeStats replayed_ns;  ///< filter time of the replay, over the compared steps
  TimeStats recorded_ns;  ///< the live filter's (safety_diagnostics_t.compute_ns), same steps
  safety::FilterCaseCounts replayed_cases{};  ///< per FilterCase, over every replayed step
  std::vector<SafetyStep> steps;              ///< in recorded nominal order
};

/// `config.safety` is the filter to replay (variant, k, ...); `reference` is
/// needed for variant qp and must outlive the call.
SafetyReplayResult ReplaySafety(const StackConfig& config, const RecordedLog& log,
                                safety::ReferenceQpSolver* reference);

// ---------------------------------------------------------------------------
// Controller

struct ControllerReplayResult {
  std::string scenario;
  /// The scenario clock starts at the first valid estimate the controller
  /// received: the sample of its first command (seq 0). When the log lacks
  /// that command, it is inferred from the first recorded one (its seq times
  /// the command period), exact for a fixed sample rate.
  int64_t time_origin_utime = -1;
  bool time_origin_inferred = false;
  long states = 0;          ///< recorded state estimates
  long invalid_states = 0;  ///< not STATUS_VALID or STATUS_DIVERGED: skipped as the node does
  long step_rejected = 0;   ///< Controller::Step returned an error: nothing published
  long replayed = 0;        ///< nominal commands the replay produced
  long recorded_commands = 0;
  long without_recorded_command = 0;  ///< replayed, none recorded with that sample_utime
  long recorded_without_replay = 0;   ///< recorded, not produced by the replay
  DiffStats nominal;                  ///< force_n; identical also needs equal flags
  long flags_differ = 0;
};

ControllerReplayResult ReplayController(const StackConfig& config, const Scenario& scenario,
                                        const RecordedLog& log);

// ---------------------------------------------------------------------------
// Estimator

struct EstimatorReplayResult {
  bool perfect_state = false;  ///< estimator.perfect_state: truth republished
  long sensor_samples = 0;
  long commands = 0;           ///< safe commands fed to the EKF
  long rejected_commands = 0;  ///< non-finite: ignored as the node does
  long replayed = 0;           ///< estimates the replay published
  long recorded_estimates = 0;
  long without_recorded_estimate = 0;
  long recorded_without_replay = 0;
  /// Sensor samples and safe commands missing from the log (seq gaps): the
  /// estimates after the first such gap cannot be reproduced.
  long inputs_missing = 0;
  int64_t inputs_intact_until_utime = -1;  ///< valid when inputs_missing > 0
  /// Over q, qd, q_std, qd_std, up to the first input gap; identical also
  /// needs equal utime and status.
  DiffStats state;
  double max_abs_diff_q = 0.0;   ///< m or rad
  double max_abs_diff_qd = 0.0;  ///< m/s or rad/s
  /// Largest difference in q_i or qd_i in sigmas of the difference of the two
  /// estimates, hypot(recorded std, replayed std).
  double max_diff_sigma = 0.0;
  long status_differ = 0;
  /// After the first input gap: reported only, not counted as differing.
  DiffStats after_gap;
  double max_abs_diff_q_after_gap = 0.0;
  double max_abs_diff_qd_after_gap = 0.0;
  double max_diff_sigma_after_gap = 0.0;
};

EstimatorReplayResult ReplayEstimator(const StackConfig& config, const RecordedLog& log);

}  // namespace stewart::replay
