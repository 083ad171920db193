#pragma once
// Offline replay of a run recorded by tools/launch.sh: the safety, controller
// and estimator processes re-run on the recorded inputs (read with
// lcm::LogFile, no network) and their outputs compared with what the live
// processes published. docs/operations.md, "Replay".
//
// Each replay drives the process's own class (SafetyProcess,
// ControllerProcess, EstimatorProcess: the decisions the node makes) with the
// recorded messages of its input channels in the order the log received them,
// and pairs what it publishes with the recorded outputs by sample_utime. So
// on the same build the replayed outputs are bit-identical to the recorded
// ones by construction.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "stewart/common/enum_table.h"
#include "stewart/common/seq_continuity.h"
#include "stewart/config/stack_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/operator_command_t.hpp"
#include "stewart/safety/reference_qp.h"
#include "stewart/safety/two_constraint_qp.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"

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
  int8_t active_case = 0;       ///< safety_diagnostics_t::CASE_*
  int32_t fallback_reason = 0;  ///< force_command_t::FLAG_* that caused a fallback
  int32_t flags = 0;            ///< the filter step's force_command_t::FLAG_*
};

enum class Channel {
  kSensors,
  kStateEstimate,
  kStateTruth,
  kCommandNominal,
  kCommandSafe,
  kSafetyDiagnostics,
  kSupervisor,  ///< supervisor_state_t: the motion clock the controller runs on
  kOperator,    ///< operator_command_t: what the live supervisor was told
  kHealth,      ///< health_t: the heartbeats the live supervisor watched
};
constexpr int kNumChannels = 9;

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
  std::vector<supervisor_state_t> supervisor;
  std::vector<operator_command_t> operator_commands;
  std::vector<health_t> health;
  /// Logger receive time (wall clock, us) of each entry of `order`.
  std::vector<int64_t> order_timestamp_us;
  /// Every decoded message above in log order: its channel and its index in
  /// that channel's vector (the estimator interleaves sensors and commands).
  std::vector<std::pair<Channel, int>> order;
  /// By Channel, each message's index in `order`.
  std::array<std::vector<long>, kNumChannels> positions;
  std::array<std::string, kNumChannels> channel_names;  ///< by Channel
  std::array<SeqGaps, kNumChannels> gaps;               ///< by Channel
  /// Every numbered stream of the log (the channels above, the heartbeats
  /// per process as <health channel>[<name>]): gaps and publisher restarts,
  /// each event's `position` its index in `order`.
  SeqContinuity continuity;
  long events = 0;                          ///< every event of the log
  std::map<std::string, long> undecodable;  ///< per stack channel
  int64_t first_timestamp_us = 0;           ///< logger receive times (wall clock)
  int64_t last_timestamp_us = 0;
  int64_t first_utime = -1;  ///< stack time span of the decoded messages (us)
  int64_t last_utime = -1;
};

/// The log's first publisher restart (a process started again during the
/// run), or nullptr: the live processes' state starts over there, the
/// replay's does not, so outputs after it are attributed to it.
inline const SeqEvent* FirstRestart(const RecordedLog& log) {
  return log.continuity.first_restart();
}

/// Whether the recorded message `index` of `channel` came at or after the
/// log's first publisher restart: a replayed output compared with it is
/// attributed to the restart.
bool RecordedAfterRestart(const RecordedLog& log, Channel channel, size_t index);

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
  /// Of those compared / differing, at or after the log's first publisher
  /// restart (FirstRestart): still counted above, and attributed to it.
  long compared_after_restart = 0;
  long differing_after_restart = 0;

  long differing() const { return compared - identical; }
  void Add(int64_t sample_utime, const double* replayed, const double* recorded, int n,
           bool other_fields_equal, bool after_restart = false);
};

/// How the outputs of one replayed process pair with the recorded ones, by
/// sample_utime.
struct OutputPairing {
  long replayed = 0;                 ///< outputs the replay published
  long recorded = 0;                 ///< outputs in the log
  long without_recorded = 0;         ///< replayed, none recorded with that sample_utime
  long recorded_without_replay = 0;  ///< recorded, not published by the replay
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

/// How one safe command the replayed process published compares with the
/// recorded one of the same sample_utime.
enum class SafetyStepKind {
  kCompared,    ///< the recorded one is the filter's answer: compared with the replay
  kFallback,    ///< the recorded one is a fallback (FLAG_FALLBACK / FLAG_STALE_INPUT)
  kUnrecorded,  ///< no recorded safe command with this sample_utime
  kLogGap,      ///< the replay's watchdog while the log lacked nominal commands: not compared
};
inline constexpr EnumTable<SafetyStepKind, 4> kSafetyStepKindNames{{{
    {SafetyStepKind::kCompared, "compared"},
    {SafetyStepKind::kFallback, "fallback"},
    {SafetyStepKind::kUnrecorded, "unrecorded"},
    {SafetyStepKind::kLogGap, "log_gap"},
}}};

/// One safe command the replayed process published.
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

/// A fault the live safety node reported to its supervisor from outside the
/// filter (supervisor_state_t.node_faults went up): its reason and the
/// sample of the newest output before it.
struct RecordedNodeFault {
  int64_t after_sample_utime = 0;
  std::string reason;
  /// Faults of the same announcement's count step whose reasons the log
  /// lacks (announcements the logger lost): heard as one.
  long unnamed = 0;
};

/// Every node fault the recorded supervisor announcements show, in order.
/// A restarted safety process (its count falls, or another session) counts
/// from zero again.
std::vector<RecordedNodeFault> RecordedNodeFaults(
    const std::vector<supervisor_state_t>& announcements);

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

  long states = 0;                ///< recorded estimates (SafetyProcess::OnState)
  long nominal_commands = 0;      ///< recorded nominal commands (SafetyProcess::OnNominal)
  long without_state = 0;         ///< nominal commands without a recorded estimate of their sample
  long answered_by_fallback = 0;  ///< nominal commands whose recorded safe command is a fallback
  OutputPairing commands;         ///< the safe commands the replay published vs the recorded
  /// kCompared: the filter's commands, replay vs recorded; identical also needs
  /// equal flags and, where recorded, equal diagnostics (case, fallback reason, flags).
  DiffStats filter;
  long flags_differ = 0;  ///< among them, force_command_t.flags differ
  /// Compared commands (either kind) whose recorded diagnostics differ from
  /// the replayed ones in case, fallback reason or flags.
  long diagnostics_differ = 0;

  /// Every recorded fallback command (FLAG_FALLBACK or FLAG_STALE_INPUT), by
  /// the path the replayed process took for it (kFallback steps).
  long fallback_commands = 0;
  long fallback_stale_input = 0;      ///< watchdog or stale nominal (FLAG_STALE_INPUT)
  long fallback_invalid_state = 0;    ///< state not usable (estimator initialising, diverged)
  long fallback_supervisor_stop = 0;  ///< the supervisor's stop (HOLD, ESTOP, DISARMED)
  long fallback_by_filter = 0;        ///< the filter's own last resort (infeasible, invalid F_des)
  long fallback_without_input = 0;    ///< not replayed: its inputs are not in the log
  DiffStats fallback;                 ///< kFallback: replay vs recorded
  /// kLogGap: watchdog fallbacks of the replay while the log lacked nominal
  /// commands (a seq gap) the live process had received.
  long log_gap = 0;
  /// The live node's faults the replayed supervisor heard, from the recorded
  /// announcements (node_faults_from_record), else judged again from the
  /// recorded heartbeats.
  bool node_faults_from_record = false;
  std::vector<RecordedNodeFault> node_faults;

  TimeStats replayed_ns;  ///< filter time of the replay, over the compared steps
  TimeStats recorded_ns;  ///< the live filter's (safety_diagnostics_t.compute_ns), same steps
  safety::FilterCaseCounts replayed_cases{};  ///< per FilterCase, over every replayed step
  std::vector<SafetyStep> steps;              ///< in the order the replay published them
};

/// SafetyProcess::OnState / OnNominal on every recorded estimate and nominal
/// command in log order; every safe command it publishes is compared with the
/// recorded one of the same sample_utime. `config.safety` is the filter to
/// replay (variant, k, ...); `reference` is needed for variant qp and must
/// outlive the call.
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
  OutputPairing commands;   ///< the nominal commands the replay published vs the recorded
  DiffStats nominal;        ///< force_n; identical also needs equal flags
  long flags_differ = 0;
};

ControllerReplayResult ReplayController(const StackConfig& config, const Scenario& scenario,
                                        const RecordedLog& log);

// ---------------------------------------------------------------------------
// Estimator

/// Replayed against recorded estimates.
struct EstimateDiff {
  /// Over q, qd, q_std, qd_std; identical also needs equal utime and status.
  DiffStats values;
  double max_abs_diff_q = 0.0;   ///< m or rad
  double max_abs_diff_qd = 0.0;  ///< m/s or rad/s
  /// Largest difference in q_i or qd_i in sigmas of the difference of the two
  /// estimates, hypot(recorded std, replayed std).
  double max_diff_sigma = 0.0;

  void Add(const state_t& replayed, const state_t& recorded, bool after_restart = false);
};

struct EstimatorReplayResult {
  bool perfect_state = false;  ///< estimator.perfect_state: truth republished
  long sensor_samples = 0;
  long commands = 0;           ///< safe commands fed to the EKF
  long rejected_commands = 0;  ///< non-finite: ignored as the node does
  OutputPairing estimates;     ///< the estimates the replay published vs the recorded
  /// Sensor samples and safe commands missing from the log (seq gaps): the
  /// estimates after the first such gap cannot be reproduced.
  long inputs_missing = 0;
  int64_t inputs_intact_until_utime = -1;  ///< valid when inputs_missing > 0
  /// Up to the first input gap.
  EstimateDiff state;
  long status_differ = 0;
  /// After the first input gap: reported only, not counted as differing.
  EstimateDiff after_gap;
};

EstimatorReplayResult ReplayEstimator(const StackConfig& config, const RecordedLog& log);

}  // namespace stewart::replay
