#include "stewart/stack/replay.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "sensor_msg.h"
#include "stewart/common/health_counters.h"
#include "stewart/controller/controller_process.h"
#include "stewart/estimator/estimator_process.h"
#include "stewart/guard/guard_limits.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/message_auth.h"
#include "stewart/node/signal_messages.h"
#include "stewart/safety/diagnostics_lcm.h"
#include "stewart/safety/process_monitor.h"
#include "stewart/safety/safety_process.h"
#include "stewart/safety_diagnostics_t.hpp"

namespace stewart::replay {
namespace {

/// The run's key (lcm.auth_key_file of its config.yaml) to recheck recorded
/// MACs as the live processes checked them. A run folder whose key is gone
/// (moved, or the key deleted) replays believing every recorded message, and
/// says so: forged commands in such a log would be believed here, not live.
MessageAuthenticator RecordedRunAuthenticator(const StackConfig& config) {
  try {
    return MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file);
  } catch (const std::exception& e) {
    spdlog::warn("replay: {}; recorded messages are believed without their MACs", e.what());
    return MessageAuthenticator();
  }
}

template <typename Msg>
bool Decode(const lcm::LogEvent& event, Msg* msg) {
  return msg->decode(event.data, 0, event.datalen) == event.datalen;
}

/// sample_utime -> index of the first message with it.
template <typename Msg>
std::unordered_map<int64_t, int> IndexBySample(const std::vector<Msg>& messages) {
  std::unordered_map<int64_t, int> index;
  index.reserve(messages.size());
  for (size_t i = 0; i < messages.size(); ++i) {
    index.emplace(messages[i].sample_utime, static_cast<int>(i));
  }
  return index;
}

template <typename Map>
const typename Map::mapped_type* Find(const Map& map, int64_t key) {
  const auto it = map.find(key);
  return it == map.end() ? nullptr : &it->second;
}

bool IsFallback(int32_t flags) {
  return (flags & (force_command_t::FLAG_FALLBACK | force_command_t::FLAG_STALE_INPUT)) != 0;
}

std::array<double, 6> ToStdArray(const Vector6d& v) {
  std::array<double, 6> a{};
  for (int i = 0; i < 6; ++i) a[static_cast<size_t>(i)] = v(i);
  return a;
}

/// A message's seq and utime.
using Stamp = std::pair<int64_t, int64_t>;

/// Decodes `event` onto the end of `messages`; its stamp, or nothing (and
/// `messages` unchanged) when it does not decode.
template <typename Msg>
std::optional<Stamp> Append(const lcm::LogEvent& event, std::vector<Msg>* messages) {
  Msg& msg = messages->emplace_back();
  if (Decode(event, &msg)) return Stamp{msg.seq, msg.utime};
  messages->pop_back();
  return std::nullopt;
}

/// `f(&messages)` with the vector of `channel`'s messages (every channel but
/// kSafetyDiagnostics, whose RecordedLog keeps only RecordedDiagnostics).
template <typename F>
std::optional<Stamp> WithMessages(RecordedLog* log, Channel channel, F f) {
  switch (channel) {
    case Channel::kSensors:
      return f(&log->sensors);
    case Channel::kStateEstimate:
      return f(&log->estimates);
    case Channel::kStateTruth:
      return f(&log->truth);
    case Channel::kCommandNominal:
      return f(&log->nominal);
    case Channel::kCommandSafe:
      return f(&log->safe);
    case Channel::kSupervisor:
      return f(&log->supervisor);
    case Channel::kOperator:
      return f(&log->operator_commands);
    case Channel::kHealth:
      return f(&log->health);
    case Channel::kSafetyDiagnostics:
      break;
  }
  return std::nullopt;
}

/// Pairs the outputs a replay publishes with the recorded messages of the
/// same sample_utime, counting both sides into an OutputPairing.
template <typename Msg>
class Pairing {
 public:
  Pairing(const std::vector<Msg>& recorded, OutputPairing* counts)
      : recorded_(recorded), index_(IndexBySample(recorded)), counts_(counts) {
    counts_->recorded = static_cast<long>(recorded.size());
  }

  /// The recorded message of `sample_utime`, or nullptr.
  const Msg* Recorded(int64_t sample_utime) const {
    const int* index = Find(index_, sample_utime);
    return index == nullptr ? nullptr : &recorded_[static_cast<size_t>(*index)];
  }
  /// A replayed output of `sample_utime`: its recorded counterpart, or nullptr.
  const Msg* Match(int64_t sample_utime) {
    ++counts_->replayed;
    replayed_.insert(sample_utime);
    const Msg* recorded = Recorded(sample_utime);
    if (recorded == nullptr) ++counts_->without_recorded;
    return recorded;
  }
  /// Whether the replay published an output of `sample_utime`.
  bool Replayed(int64_t sample_utime) const { return replayed_.count(sample_utime) != 0; }
  /// After the replay: counts the recorded messages no output matched.
  void Finish() {
    for (const Msg& recorded : recorded_) {
      if (!Replayed(recorded.sample_utime)) ++counts_->recorded_without_replay;
    }
  }

 private:
  const std::vector<Msg>& recorded_;
  const std::unordered_map<int64_t, int> index_;
  OutputPairing* counts_;
  std::unordered_set<int64_t> replayed_;
};

}  // namespace

RecordedLog ReadLog(const std::string& path, const ChannelNames& channels) {
  lcm::LogFile file(path, "r");
  if (!file.good()) throw InputError("cannot open the LCM log '" + path + "'");
  const std::unordered_map<std::string, Channel> routes = {
      {channels.sensors, Channel::kSensors},
      {channels.state_estimate, Channel::kStateEstimate},
      {channels.state_truth, Channel::kStateTruth},
      {channels.command_nominal, Channel::kCommandNominal},
      {channels.command_safe, Channel::kCommandSafe},
      {channels.safety_diagnostics, Channel::kSafetyDiagnostics},
      {channels.supervisor, Channel::kSupervisor},
      {channels.operator_command, Channel::kOperator},
      {channels.health, Channel::kHealth},
  };
  RecordedLog log;
  for (const auto& [name, channel] : routes) log.channel_names[static_cast<size_t>(channel)] = name;
  // Every publisher starts at seq 0 and counts by one: a seq that skips is
  // a gap (published, not recorded), one that falls back a restarted
  // publisher (SeqContinuity).
  auto track = [&log](Channel channel, const std::string& stream, int64_t seq, int64_t utime,
                      int64_t timestamp) {
    const long position = static_cast<long>(log.order.size()) - 1;
    const std::optional<SeqEvent> event =
        log.continuity.Observe(stream, seq, utime, timestamp, position);
    // A heartbeat's utime is its process's newest input (0 before any):
    // neither a data channel's gap nor the stack's time span.
    if (channel == Channel::kHealth) return;
    if (event && event->missing > 0) {
      SeqGaps& gaps = log.gaps[static_cast<size_t>(channel)];
      if (gaps.gaps == 0) {
        gaps.intact_until_utime = event->previous_seq >= 0 ? event->previous_utime : utime - 1;
      }
      ++gaps.gaps;
      gaps.missing += event->missing;
    }
    if (log.first_utime < 0 || utime < log.first_utime) log.first_utime = utime;
    log.last_utime = std::max(log.last_utime, utime);
  };
  safety_diagnostics_t diagnostics;  // reused: keeps its string and array capacities
  while (const lcm::LogEvent* event = file.readNextEvent()) {
    if (log.events == 0) log.first_timestamp_us = event->timestamp;
    log.last_timestamp_us = event->timestamp;
    ++log.events;
    const auto route = routes.find(event->channel);
    if (route == routes.end()) continue;
    const Channel channel = route->second;
    int index = 0;
    std::optional<Stamp> stamp;
    if (channel == Channel::kSafetyDiagnostics) {
      index = static_cast<int>(log.diagnostics.size());
      if (Decode(*event, &diagnostics)) {
        log.diagnostics.push_back({diagnostics.sample_utime, diagnostics.compute_ns,
                                   diagnostics.variant, diagnostics.force_limits != 0,
                                   diagnostics.active_case, diagnostics.fallback_reason,
                                   diagnostics.flags});
        stamp = Stamp{diagnostics.seq, diagnostics.utime};
      }
    } else {
      stamp = WithMessages(&log, channel, [&](auto* messages) {
        index = static_cast<int>(messages->size());
        return Append(*event, messages);
      });
    }
    if (stamp) {
      log.positions[static_cast<size_t>(channel)].push_back(static_cast<long>(log.order.size()));
      log.order.emplace_back(channel, index);
      log.order_timestamp_us.push_back(event->timestamp);
      // Operator commands: consoles share the channel and number their
      // commands each, from any start: no stream. Heartbeats: one stream
      // per process.
      if (channel == Channel::kHealth) {
        const health_t& h = log.health.back();
        track(channel, event->channel + "[" + h.name + "]", stamp->first, stamp->second,
              event->timestamp);
      } else if (channel != Channel::kOperator) {
        track(channel, event->channel, stamp->first, stamp->second, event->timestamp);
      }
    } else {
      ++log.undecodable[event->channel];
    }
  }
  if (log.events == 0) {
    throw InputError("'" + path + "' holds no LCM event (empty, or not an LCM log)");
  }
  return log;
}

bool RecordedAfterRestart(const RecordedLog& log, Channel channel, size_t index) {
  const SeqEvent* restart = FirstRestart(log);
  const std::vector<long>& positions = log.positions[static_cast<size_t>(channel)];
  return restart != nullptr && index < positions.size() && positions[index] >= restart->position;
}

void DiffStats::Add(int64_t sample_utime, const double* replayed, const double* recorded, int n,
                    bool other_fields_equal, bool after_restart) {
  ++compared;
  const size_t bytes = sizeof(double) * static_cast<size_t>(n);
  const bool same = other_fields_equal && std::memcmp(replayed, recorded, bytes) == 0;
  if (same) ++identical;
  if (after_restart) {
    ++compared_after_restart;
    if (!same) ++differing_after_restart;
  }
  double diff = 0.0;
  double scale = 0.0;
  for (int i = 0; i < n; ++i) {
    diff = std::fmax(diff, std::fabs(replayed[i] - recorded[i]));
    scale = std::fmax(scale, std::fabs(recorded[i]));
  }
  if (diff > max_abs_diff) {
    max_abs_diff = diff;
    worst_sample_utime = sample_utime;
  }
  if (diff > 0.0) {
    max_rel_diff = std::fmax(max_rel_diff, scale > 0.0 ? diff / scale : HUGE_VAL);
  }
}

TimeStats ComputeTimeStats(std::vector<int64_t> ns) {
  TimeStats s;
  s.count = static_cast<long>(ns.size());
  if (ns.empty()) return s;
  std::sort(ns.begin(), ns.end());
  auto percentile = [&ns](double p) {
    const double rank = p / 100.0 * static_cast<double>(ns.size() - 1);
    const size_t lo = static_cast<size_t>(std::floor(rank));
    const size_t hi = std::min(lo + 1, ns.size() - 1);
    const double frac = rank - static_cast<double>(lo);
    return static_cast<double>(ns[lo]) +
           frac * (static_cast<double>(ns[hi]) - static_cast<double>(ns[lo]));
  };
  s.p50_ns = percentile(50.0);
  s.p99_ns = percentile(99.0);
  s.max_ns = static_cast<double>(ns.back());
  return s;
}

std::vector<RecordedNodeFault> RecordedNodeFaults(
    const std::vector<supervisor_state_t>& announcements) {
  std::vector<RecordedNodeFault> faults;
  int64_t session = 0;
  int64_t heard = 0;
  for (const supervisor_state_t& a : announcements) {
    if (a.session_id != session || a.node_faults < heard) {
      session = a.session_id;
      heard = 0;
    }
    if (a.node_faults > heard) {
      faults.push_back(
          {a.sample_utime, a.last_node_fault, static_cast<long>(a.node_faults - heard - 1)});
      heard = a.node_faults;
    }
  }
  return faults;
}

SafetyReplayResult ReplaySafety(const StackConfig& config, const RecordedLog& log,
                                safety::ReferenceQpSolver* reference) {
  SafetyReplayResult r;
  // The process's own class, built exactly as the live node built it.
  HealthCounters counters("safety replay");
  // No receive times: the time checks judge message times only, so a log
  // replays to the same outputs whenever and however fast it is replayed.
  safety::SafetyProcess process(config.platform, config.safety, config.actuators, config.supervisor,
                                reference, &counters, config.lcm.time_plausibility);
  const safety::SafetyFilter& filter = process.filter();
  r.variant = filter.variant();
  if (r.variant == SafetyVariant::kQpReference && reference != nullptr) {
    r.qp_solver = reference->name();
  }
  r.force_limits = filter.force_limits();
  r.k_position = config.safety.k_position;
  r.k_velocity = config.safety.k_velocity;

  // What the live filter was: the most frequent variant in its diagnostics.
  if (!log.diagnostics.empty()) {
    std::map<int8_t, long> variants;
    long limited = 0;
    for (const RecordedDiagnostics& d : log.diagnostics) {
      ++variants[d.variant];
      limited += d.force_limits ? 1 : 0;
    }
    const auto most =
        std::max_element(variants.begin(), variants.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    r.recorded_variant = safety::FromLcmVariant(most->first);
    r.recorded_force_limits = 2 * limited > static_cast<long>(log.diagnostics.size());
  }

  const auto state_of = IndexBySample(log.estimates);
  Pairing<force_command_t> safe(log.safe, &r.commands);
  std::unordered_map<int64_t, int> diagnostics_of;
  for (size_t i = 0; i < log.diagnostics.size(); ++i) {
    diagnostics_of.emplace(log.diagnostics[i].sample_utime, static_cast<int>(i));
  }
  r.nominal_commands = static_cast<long>(log.nominal.size());
  for (const force_command_t& nominal : log.nominal) {
    if (Find(state_of, nominal.sample_utime) == nullptr) ++r.without_state;
    const force_command_t* recorded = safe.Recorded(nominal.sample_utime);
    if (recorded != nullptr && IsFallback(recorded->flags)) ++r.answered_by_fallback;
  }

  // One safe command the process published, against the recorded one; its
  // diagnostics (case, fallback reason, flags) against the recorded ones.
  std::vector<int64_t> replayed_ns, recorded_ns;
  safety_diagnostics_t replayed_diagnostics;  // reused: keeps its capacities
  auto compare = [&](const safety::SafetyOutput& out, bool watchdog_in_gap) {
    SafetyStep step;
    step.sample_utime = out.command.sample_utime;
    step.f_replayed = ToStdArray(out.command.force_n);
    step.replayed_flags = out.command.flags;
    step.replayed_case = static_cast<int8_t>(out.diagnostics->filter_case);
    step.replayed_ns = out.diagnostics->compute_ns;
    ++r.replayed_cases[static_cast<size_t>(step.replayed_case)];
    const force_command_t* recorded = safe.Match(step.sample_utime);
    if (recorded == nullptr) {
      step.kind = SafetyStepKind::kUnrecorded;
      r.steps.push_back(step);
      return;
    }
    std::copy(std::begin(recorded->force_n), std::end(recorded->force_n), step.f_recorded.begin());
    step.recorded_flags = recorded->flags;
    const bool after_restart = RecordedAfterRestart(
        log, Channel::kCommandSafe, static_cast<size_t>(recorded - log.safe.data()));
    bool diagnostics_equal = true;
    if (const int* diag_index = Find(diagnostics_of, step.sample_utime)) {
      const RecordedDiagnostics& d = log.diagnostics[static_cast<size_t>(*diag_index)];
      step.recorded_ns = d.compute_ns;
      safety::FillDiagnosticsMessage(process.filter(), out, &replayed_diagnostics);
      diagnostics_equal = d.active_case == replayed_diagnostics.active_case &&
                          d.fallback_reason == replayed_diagnostics.fallback_reason &&
                          d.flags == replayed_diagnostics.flags;
      if (!diagnostics_equal && !watchdog_in_gap) ++r.diagnostics_differ;
    }
    const bool flags_equal = recorded->flags == step.replayed_flags;
    const bool others_equal = flags_equal && diagnostics_equal;
    if (watchdog_in_gap) {
      // The live watchdog had nominal commands the log lacks.
      step.kind = SafetyStepKind::kLogGap;
      ++r.log_gap;
    } else if (IsFallback(recorded->flags)) {
      step.kind = SafetyStepKind::kFallback;
      if (out.fallback_reason == kCommandStaleInput) {
        ++r.fallback_stale_input;
      } else if (out.fallback_reason == kCommandInvalidInput) {
        ++r.fallback_invalid_state;
      } else if (out.mode.state != safety::SupervisorState::kArming &&
                 out.mode.state != safety::SupervisorState::kArmed) {
        ++r.fallback_supervisor_stop;
      } else {
        ++r.fallback_by_filter;
      }
      r.fallback.Add(step.sample_utime, step.f_replayed.data(), recorded->force_n, 6, others_equal,
                     after_restart);
    } else {
      step.kind = SafetyStepKind::kCompared;
      if (!flags_equal) ++r.flags_differ;
      r.filter.Add(step.sample_utime, step.f_replayed.data(), recorded->force_n, 6, others_equal,
                   after_restart);
      replayed_ns.push_back(step.replayed_ns);
      if (step.recorded_ns >= 0) recorded_ns.push_back(step.recorded_ns);
    }
    r.steps.push_back(step);
  };

  // SafetyProcess::OnState / OnNominal in the order the log received them.
  // Until the next recorded nominal command, the log lacks nominal commands
  // the live process had when that one follows a gap in seq (or the log's
  // first is not seq 0): a watchdog fallback (OnState, stale input) then is
  // the log's, not the process's.
  size_t nominal_next = 0;
  auto lacking_nominal = [&log, &nominal_next] {
    if (nominal_next >= log.nominal.size()) return false;
    const int64_t expected = nominal_next == 0 ? 0 : log.nominal[nominal_next - 1].seq + 1;
    return log.nominal[nominal_next].seq > expected;
  };
  r.steps.reserve(log.nominal.size());
  // The faults the live node reported to its supervisor (heartbeats, a
  // stall, the dead-man) were judged on its wall clock: the recorded
  // announcements say which and after which sample, and the replay's
  // supervisor hears each between the same two outputs. Without any
  // announcement in the log, they are judged again from the recorded
  // heartbeats on the logger's receive times, an approximation.
  const std::vector<RecordedNodeFault> node_faults = RecordedNodeFaults(log.supervisor);
  const bool faults_from_record = !log.supervisor.empty();
  r.node_faults_from_record = faults_from_record;
  size_t node_fault_next = 0;
  auto hear_recorded_faults = [&] {
    while (node_fault_next < node_faults.size() &&
           node_faults[node_fault_next].after_sample_utime <= process.supervisor().sample_utime()) {
      process.supervisor().OnFault(node_faults[node_fault_next].reason);
      r.node_faults.push_back(node_faults[node_fault_next]);
      ++node_fault_next;
    }
  };
  // What else the live supervisor heard: the operator's commands and the
  // heartbeats, in log order (whether the processes were healthy when an
  // operator armed is judged on the logger's receive times).
  safety::ProcessMonitor monitor(config.supervisor.required_processes,
                                 std::llround(config.supervisor.heartbeat_timeout_s * 1e6));
  for (size_t e = 0; e < log.order.size(); ++e) {
    const auto& [channel, index] = log.order[e];
    const int64_t timestamp_us = log.order_timestamp_us[e];
    const safety::SupervisorState state = process.supervisor().state();
    monitor.SetMoving(
        state == safety::SupervisorState::kArming || state == safety::SupervisorState::kArmed,
        timestamp_us);
    for (const std::string& fault : monitor.CheckSilence(timestamp_us)) {
      if (!faults_from_record) process.supervisor().OnFault(fault);
    }
    if (channel == Channel::kOperator) {
      const operator_command_t& op = log.operator_commands[static_cast<size_t>(index)];
      if (op.command >= static_cast<int8_t>(safety::OperatorCommand::kArm) &&
          op.command <= static_cast<int8_t>(safety::OperatorCommand::kHeartbeat)) {
        std::string why_not;
        const bool healthy = monitor.Healthy(timestamp_us, &why_not);
        process.supervisor().OnOperator(static_cast<safety::OperatorCommand>(op.command), healthy,
                                        why_not, nullptr);
      }
      continue;
    }
    if (channel == Channel::kHealth) {
      const health_t& h = log.health[static_cast<size_t>(index)];
      const std::string fault = monitor.OnHeartbeat(h.name, h.state, h.seq, timestamp_us);
      if (!fault.empty() && !faults_from_record) process.supervisor().OnFault(fault);
      continue;
    }
    if (channel != Channel::kStateEstimate && channel != Channel::kCommandNominal) continue;
    hear_recorded_faults();
    safety::SafetyOutput out;
    if (channel == Channel::kStateEstimate) {
      ++r.states;
      if (process.OnState(FromMessage(log.estimates[static_cast<size_t>(index)]), &out)) {
        compare(out, out.fallback_reason == kCommandStaleInput && lacking_nominal());
      }
    } else if (channel == Channel::kCommandNominal) {
      ++nominal_next;
      if (process.OnNominal(FromMessage(log.nominal[static_cast<size_t>(index)]), &out)) {
        compare(out, false);
      }
    }
  }
  safe.Finish();
  r.replayed_ns = ComputeTimeStats(std::move(replayed_ns));
  r.recorded_ns = ComputeTimeStats(std::move(recorded_ns));
  for (const force_command_t& recorded : log.safe) {
    if (IsFallback(recorded.flags)) ++r.fallback_commands;
  }
  r.fallback_without_input = r.fallback_commands - r.fallback_stale_input -
                             r.fallback_invalid_state - r.fallback_supervisor_stop -
                             r.fallback_by_filter;
  return r;
}

namespace {

std::optional<int64_t> ControllerTimeOrigin(const RecordedLog& log, bool* inferred) {
  *inferred = false;
  const force_command_t* first = nullptr;
  for (const force_command_t& command : log.nominal) {
    if (first == nullptr || command.seq < first->seq) first = &command;
  }
  if (first == nullptr) return std::nullopt;
  if (first->seq == 0) return first->sample_utime;
  // The command period: the median step between recorded consecutive commands.
  std::vector<int64_t> steps;
  for (size_t i = 1; i < log.nominal.size(); ++i) {
    if (log.nominal[i].seq == log.nominal[i - 1].seq + 1) {
      steps.push_back(log.nominal[i].sample_utime - log.nominal[i - 1].sample_utime);
    }
  }
  if (steps.empty()) return std::nullopt;
  std::nth_element(steps.begin(), steps.begin() + static_cast<long>(steps.size() / 2), steps.end());
  *inferred = true;
  return first->sample_utime - first->seq * steps[steps.size() / 2];
}

}  // namespace

ControllerReplayResult ReplayController(const StackConfig& config, const Scenario& scenario,
                                        const RecordedLog& log) {
  ControllerReplayResult r;
  r.scenario = scenario.name();
  HealthCounters counters("controller replay");
  ControllerProcess process(config.platform, config.controller, config.home_pose, scenario,
                            &counters, config.lcm.time_plausibility);
  Pairing<force_command_t> recorded_commands(log.nominal, &r.commands);
  const std::optional<int64_t> origin = ControllerTimeOrigin(log, &r.time_origin_inferred);
  r.time_origin_utime = origin.value_or(-1);
  bool started = false;
  // The process's OnState per recorded estimate, and its OnSupervisor per
  // recorded supervisor state (the motion clock), in log order.
  for (const auto& [channel, index] : log.order) {
    if (channel == Channel::kSupervisor) {
      const supervisor_state_t& sup = log.supervisor[static_cast<size_t>(index)];
      process.OnSupervisor(sup.utime, sup.motion_time_us,
                           sup.state == supervisor_state_t::STATE_ARMING ||
                               sup.state == supervisor_state_t::STATE_ARMED);
      continue;
    }
    if (channel != Channel::kStateEstimate) continue;
    const state_t& state_msg = log.estimates[static_cast<size_t>(index)];
    ++r.states;
    const StateSample state = FromMessage(state_msg);
    ControllerProcessOutput out;
    if (!started && origin && *origin < state.utime && StateUsable(state)) {
      // The first state the live controller stepped on is not in the log:
      // start the clock there (this step's output is not compared).
      StateSample at_origin = state;
      at_origin.utime = *origin;
      process.OnState(at_origin, &out);
    }
    const ControllerVerdict verdict = process.OnState(state, &out);
    if (verdict == ControllerVerdict::kStateNotUsable) {
      ++r.invalid_states;
      continue;
    }
    started = true;
    if (verdict == ControllerVerdict::kStepRejected ||
        verdict == ControllerVerdict::kTimeImplausible) {
      ++r.step_rejected;
      continue;
    }
    force_command_t command{};
    ToMessage(out.command, &command);
    const force_command_t* recorded = recorded_commands.Match(state.sample_utime);
    if (recorded == nullptr) continue;
    const bool flags_equal = recorded->flags == command.flags;
    if (!flags_equal) ++r.flags_differ;
    r.nominal.Add(state.sample_utime, command.force_n, recorded->force_n, 6, flags_equal,
                  RecordedAfterRestart(log, Channel::kCommandNominal,
                                       static_cast<size_t>(recorded - log.nominal.data())));
  }
  recorded_commands.Finish();
  return r;
}

namespace {

// q, qd, q_std, qd_std, disturbance and its std of a state in one array.
std::array<double, 36> StateValues(const state_t& s) {
  std::array<double, 36> v{};
  std::copy(std::begin(s.q), std::end(s.q), v.begin());
  std::copy(std::begin(s.qd), std::end(s.qd), v.begin() + 6);
  std::copy(std::begin(s.q_std), std::end(s.q_std), v.begin() + 12);
  std::copy(std::begin(s.qd_std), std::end(s.qd_std), v.begin() + 18);
  std::copy(std::begin(s.disturbance), std::end(s.disturbance), v.begin() + 24);
  std::copy(std::begin(s.disturbance_std), std::end(s.disturbance_std), v.begin() + 30);
  return v;
}

bool EstimateFinite(const state_t& s) {
  return AllFinite(s.q) && AllFinite(s.qd) && AllFinite(s.q_std) && AllFinite(s.qd_std) &&
         AllFinite(s.disturbance) && AllFinite(s.disturbance_std);
}

}  // namespace

void EstimateDiff::Add(const state_t& replayed, const state_t& recorded, bool after_restart) {
  const auto a = StateValues(replayed);
  const auto b = StateValues(recorded);
  values.Add(replayed.sample_utime, a.data(), b.data(), static_cast<int>(a.size()),
             recorded.status == replayed.status && recorded.utime == replayed.utime, after_restart);
  // In sigmas of the difference of two estimates: hypot(std_a, std_b).
  auto sigmas = [](double diff, double std_a, double std_b) {
    const double std = std::hypot(std_a, std_b);
    return std > 0.0 ? diff / std : 0.0;
  };
  for (int i = 0; i < 6; ++i) {
    const double dq = std::fabs(replayed.q[i] - recorded.q[i]);
    const double dqd = std::fabs(replayed.qd[i] - recorded.qd[i]);
    max_abs_diff_q = std::fmax(max_abs_diff_q, dq);
    max_abs_diff_qd = std::fmax(max_abs_diff_qd, dqd);
    max_diff_sigma =
        std::fmax(max_diff_sigma, std::fmax(sigmas(dq, recorded.q_std[i], replayed.q_std[i]),
                                            sigmas(dqd, recorded.qd_std[i], replayed.qd_std[i])));
  }
}

EstimatorReplayResult ReplayEstimator(const StackConfig& config, const RecordedLog& log) {
  EstimatorReplayResult r;
  r.perfect_state = config.estimator.perfect_state;
  // Up to the first sample or command missing from the log, the replay has
  // every input the live estimator had.
  for (Channel input : r.perfect_state
                           ? std::vector<Channel>{Channel::kStateTruth}
                           : std::vector<Channel>{Channel::kSensors, Channel::kCommandSafe}) {
    const SeqGaps& gaps = log.gaps[static_cast<size_t>(input)];
    if (gaps.gaps == 0) continue;
    if (r.inputs_missing == 0 || gaps.intact_until_utime < r.inputs_intact_until_utime) {
      r.inputs_intact_until_utime = gaps.intact_until_utime;
    }
    r.inputs_missing += gaps.missing;
  }
  Pairing<state_t> recorded_estimates(log.estimates, &r.estimates);
  HealthCounters counters("estimator replay");
  // The live estimator believes the safe commands the actuators would apply
  // (the announced session, its MAC): replay decides the same from the log.
  EstimatorProcess process(config.platform, config.actuators, config.sensors, config.estimator,
                           config.home_pose, &counters, config.lcm.time_plausibility,
                           AcceptorLimitsOf(config.guard, config.estimator.command_timeout_s),
                           config.guard.leg_force_limit_n);
  MessageAuthenticator auth = RecordedRunAuthenticator(config);
  auto compare = [&](const StateSample& sample) {
    state_t replayed{};
    ToMessage(sample, &replayed);
    // EstimatorNode::Publish drops non-finite estimates.
    if (!EstimateFinite(replayed)) return;
    const state_t* match = recorded_estimates.Match(replayed.sample_utime);
    if (match == nullptr) return;
    const state_t& recorded = *match;
    const bool intact =
        r.inputs_missing == 0 || replayed.sample_utime <= r.inputs_intact_until_utime;
    if (recorded.status != replayed.status && intact) ++r.status_differ;
    (intact ? r.state : r.after_gap)
        .Add(replayed, recorded,
             RecordedAfterRestart(log, Channel::kStateEstimate,
                                  static_cast<size_t>(&recorded - log.estimates.data())));
  };

  if (r.perfect_state) {
    // EstimatorProcess::OnTruth: the ground truth, republished.
    for (const state_t& truth : log.truth) {
      StateSample state;
      if (process.OnTruth(FromMessage(truth), &state)) compare(state);
    }
  } else {
    // EstimatorProcess::OnAnnouncement / OnCommand / OnSensor, in the order
    // the log received them (the logger's receive time as the wall clock).
    for (size_t e = 0; e < log.order.size(); ++e) {
      const auto& [channel, index] = log.order[e];
      if (channel == Channel::kSupervisor) {
        const supervisor_state_t& sup = log.supervisor[static_cast<size_t>(index)];
        process.OnAnnouncement(SessionAnnouncement{sup.utime, sup.seq, sup.session_id},
                               auth.Verify(sup), log.order_timestamp_us[e]);
      } else if (channel == Channel::kCommandSafe) {
        const force_command_t& command = log.safe[static_cast<size_t>(index)];
        ++r.commands;
        if (!AllFinite(command.force_n)) ++r.rejected_commands;
        // A sample that waited for this answer is estimated now.
        StateSample state;
        if (process.OnCommand(FromMessage(command), &state, std::nullopt, auth.Verify(command))) {
          compare(state);
        }
      } else if (channel == Channel::kSensors) {
        ++r.sensor_samples;
        StateSample state;
        if (process.OnSensor(SampleFromMessage(log.sensors[static_cast<size_t>(index)]), &state)) {
          compare(state);
        }
      }
    }
  }
  recorded_estimates.Finish();
  return r;
}

}  // namespace stewart::replay
