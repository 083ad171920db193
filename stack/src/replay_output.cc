#include "stewart/stack/replay_output.h"

#include <spdlog/fmt/fmt.h>

#include <cmath>
#include <iomanip>

namespace stewart::replay {
namespace {

using nlohmann::ordered_json;

// JSON has no inf or NaN: null instead.
ordered_json Number(double value) {
  return std::isfinite(value) ? ordered_json(value) : ordered_json(nullptr);
}

ordered_json ToJson(const DiffStats& d, const char* unit_suffix) {
  ordered_json j;
  j["compared"] = d.compared;
  j["identical"] = d.identical;
  j[std::string("max_abs_diff") + unit_suffix] = Number(d.max_abs_diff);
  j["max_rel_diff"] = Number(d.max_rel_diff);
  j["worst_sample_utime"] = d.worst_sample_utime;
  j["compared_after_restart"] = d.compared_after_restart;
  j["differing_after_restart"] = d.differing_after_restart;
  return j;
}

ordered_json ToJson(const TimeStats& t) {
  ordered_json j;
  j["count"] = t.count;
  j["p50"] = t.count ? Number(t.p50_ns) : ordered_json(nullptr);
  j["p99"] = t.count ? Number(t.p99_ns) : ordered_json(nullptr);
  j["max"] = t.count ? Number(t.max_ns) : ordered_json(nullptr);
  return j;
}

/// An OutputPairing under its replay's names: "recorded_<noun>s",
/// "without_recorded_<noun>".
ordered_json ToJson(const OutputPairing& p, const std::string& noun) {
  return {{"replayed", p.replayed},
          {"recorded_" + noun + "s", p.recorded},
          {"without_recorded_" + noun, p.without_recorded},
          {"recorded_without_replay", p.recorded_without_replay}};
}

ordered_json ToJson(const EstimateDiff& d) {
  ordered_json j = ToJson(d.values, "");
  j["max_abs_diff_q"] = Number(d.max_abs_diff_q);
  j["max_abs_diff_qd"] = Number(d.max_abs_diff_qd);
  j["max_diff_sigma"] = Number(d.max_diff_sigma);
  return j;
}

ordered_json ToJson(const SafetyReplayResult& s, const std::string& variant_source) {
  ordered_json j = {
      {"variant", ToString(s.variant)},
      {"variant_source", variant_source},
      {"qp_solver", s.qp_solver.empty() ? ordered_json(nullptr) : ordered_json(s.qp_solver)},
      {"force_limits", s.force_limits},
      {"k_position", s.k_position},
      {"k_velocity", s.k_velocity},
      {"recorded_variant",
       s.recorded_variant ? ordered_json(ToString(*s.recorded_variant)) : ordered_json(nullptr)},
      {"recorded_force_limits",
       s.recorded_force_limits ? ordered_json(*s.recorded_force_limits) : ordered_json(nullptr)},
      {"states", s.states},
      {"nominal_commands", s.nominal_commands},
      {"without_state", s.without_state}};
  j.update(ToJson(s.commands, "command"));
  j["answered_by_fallback"] = s.answered_by_fallback;
  j["log_gap"] = s.log_gap;
  j.update(ToJson(s.filter, "_n"));
  j["flags_differ"] = s.flags_differ;
  j["diagnostics_differ"] = s.diagnostics_differ;
  ordered_json fallback = {
      {"recorded", s.fallback_commands},           {"stale_input", s.fallback_stale_input},
      {"invalid_state", s.fallback_invalid_state}, {"supervisor_stop", s.fallback_supervisor_stop},
      {"by_filter", s.fallback_by_filter},         {"without_input", s.fallback_without_input}};
  fallback.update(ToJson(s.fallback, "_n"));
  j["fallback"] = fallback;
  ordered_json node_faults = ordered_json::array();
  for (const RecordedNodeFault& f : s.node_faults) {
    node_faults.push_back({{"after_sample_utime", f.after_sample_utime},
                           {"reason", f.reason},
                           {"unnamed", f.unnamed}});
  }
  j["node_faults"] = {{"source", s.node_faults_from_record ? "recorded" : "heartbeats"},
                      {"heard", node_faults}};
  j["compute_ns"] = {{"replayed", ToJson(s.replayed_ns)}, {"recorded", ToJson(s.recorded_ns)}};
  ordered_json cases;
  for (size_t i = 0; i < s.replayed_cases.size(); ++i) {
    cases[std::string(safety::kFilterCaseNames.entries[i].second)] = s.replayed_cases[i];
  }
  j["replayed_cases"] = cases;
  return j;
}

ordered_json ToJson(const ControllerReplayResult& c) {
  ordered_json j = {{"scenario", c.scenario},
                    {"time_origin_utime", c.time_origin_utime},
                    {"time_origin_inferred", c.time_origin_inferred},
                    {"states", c.states},
                    {"invalid_states", c.invalid_states},
                    {"step_rejected", c.step_rejected}};
  j.update(ToJson(c.commands, "command"));
  j.update(ToJson(c.nominal, "_n"));
  j["flags_differ"] = c.flags_differ;
  return j;
}

ordered_json ToJson(const EstimatorReplayResult& e) {
  ordered_json j = {{"perfect_state", e.perfect_state},
                    {"sensor_samples", e.sensor_samples},
                    {"commands", e.commands},
                    {"rejected_commands", e.rejected_commands}};
  j.update(ToJson(e.estimates, "estimate"));
  j.update(ToJson(e.state));
  j["status_differ"] = e.status_differ;
  j["inputs_missing"] = e.inputs_missing;
  j["inputs_intact_until_utime"] = e.inputs_intact_until_utime;
  j["after_gap"] = ToJson(e.after_gap);
  return j;
}

std::string Unmatched(const OutputPairing& p) {
  return fmt::format(
      "  unmatched             {} replayed without a recorded one, {} recorded without a "
      "replayed one\n",
      p.without_recorded, p.recorded_without_replay);
}

std::string Us(const TimeStats& t) {
  if (t.count == 0) return "n/a";
  return fmt::format("p50 {:.2f} us, p99 {:.2f} us", t.p50_ns * 1e-3, t.p99_ns * 1e-3);
}

std::string Identical(const DiffStats& d) {
  std::string o = fmt::format("{} compared, {} bit-identical", d.compared, d.identical);
  if (d.compared_after_restart > 0) {
    o += fmt::format(" ({} compared after the restart, {} of them differ)",
                     d.compared_after_restart, d.differing_after_restart);
  }
  return o;
}

std::string Worst(const DiffStats& d, const char* unit) {
  if (d.max_abs_diff == 0.0) return fmt::format("max |d| 0 {}", unit);
  return fmt::format("max |d| {:.3g} {} (sample_utime {}), max relative {:.3g}", d.max_abs_diff,
                     unit, d.worst_sample_utime, d.max_rel_diff);
}

double StackDurationS(const RecordedLog& log) {
  return log.first_utime < 0 ? 0.0 : 1e-6 * static_cast<double>(log.last_utime - log.first_utime);
}

/// Seconds from the log's first event to `timestamp_us` (the logger's clock).
double LogTimeS(const RecordedLog& log, int64_t timestamp_us) {
  return 1e-6 * static_cast<double>(timestamp_us - log.first_timestamp_us);
}

/// The first restart, as the summary names it.
std::string DescribeRestart(const RecordedLog& log, const SeqEvent& e) {
  return fmt::format("{} at utime {} (log +{:.3f} s, seq {} -> {})", e.stream, e.utime,
                     LogTimeS(log, e.log_utime), e.previous_seq, e.seq);
}

}  // namespace

long ReplayReport::Differing() const {
  long n = 0;
  if (safety) n += safety->filter.differing() + safety->fallback.differing();
  if (controller) n += controller->nominal.differing();
  if (estimator) n += estimator->state.values.differing();
  return n;
}

long ReplayReport::DifferingAfterRestart() const {
  long n = 0;
  if (safety)
    n += safety->filter.differing_after_restart + safety->fallback.differing_after_restart;
  if (controller) n += controller->nominal.differing_after_restart;
  if (estimator) n += estimator->state.values.differing_after_restart;
  return n;
}

long ReplayReport::Compared() const {
  long n = 0;
  if (safety) n += safety->filter.compared + safety->fallback.compared;
  if (controller) n += controller->nominal.compared;
  if (estimator) n += estimator->state.values.compared;
  return n;
}

ordered_json ToJson(const ReplayReport& report) {
  ordered_json j;
  j["tool"] = "stewart_replay";
  j["run"] = report.run_dir;
  j["log"] = report.log_path;
  j["config"] = report.config_path;
  if (!report.scenario_path.empty()) j["scenario"] = report.scenario_path;
  const RecordedLog& log = *report.log;
  j["log_events"] = log.events;
  j["log_wall_duration_s"] =
      1e-6 * static_cast<double>(log.last_timestamp_us - log.first_timestamp_us);
  j["stack_duration_s"] = StackDurationS(log);
  j["undecodable"] = log.undecodable;
  ordered_json gaps = ordered_json::object();
  for (size_t c = 0; c < log.gaps.size(); ++c) {
    if (log.gaps[c].gaps == 0) continue;
    gaps[log.channel_names[c]] = {{"missing", log.gaps[c].missing},
                                  {"gaps", log.gaps[c].gaps},
                                  {"intact_until_utime", log.gaps[c].intact_until_utime}};
  }
  j["log_gaps"] = gaps;
  ordered_json restarts = ordered_json::array();
  for (const SeqEvent& e : log.continuity.events()) {
    if (e.kind != SeqEventKind::kRestart) continue;
    restarts.push_back({{"stream", e.stream},
                        {"utime", e.utime},
                        {"log_time_s", LogTimeS(log, e.log_utime)},
                        {"previous_seq", e.previous_seq},
                        {"seq", e.seq},
                        {"missing", e.missing}});
  }
  j["log_restarts"] = restarts;

  if (report.safety) j["safety"] = ToJson(*report.safety, report.variant_source);
  if (report.controller) j["controller"] = ToJson(*report.controller);
  if (report.estimator) j["estimator"] = ToJson(*report.estimator);
  j["compared"] = report.Compared();
  j["differing"] = report.Differing();
  j["differing_after_restart"] = report.DifferingAfterRestart();
  j["identical"] = report.Differing() == 0;
  return j;
}

std::string FormatSummary(const ReplayReport& report) {
  const RecordedLog& log = *report.log;
  std::string o = fmt::format("stewart_replay: {}\n", report.run_dir);
  o += fmt::format("  log     {}: {} events, {:.3f} s of stack time (logged in {:.1f} s)",
                   report.log_path, log.events, StackDurationS(log),
                   1e-6 * static_cast<double>(log.last_timestamp_us - log.first_timestamp_us));
  for (const auto& [channel, count] : log.undecodable) {
    o += fmt::format(", {} undecodable on {}", count, channel);
  }
  // What the log lacks and where a publisher started again, before any
  // difference: both explain differences below.
  long restarts = 0;
  for (const SeqEvent& e : log.continuity.events()) {
    if (e.kind != SeqEventKind::kRestart) continue;
    if (++restarts > 10) continue;
    o += fmt::format(
        "\n  restart {}: seq fell back from {} to {} at utime {} (log +{:.3f} s): its publisher "
        "started again",
        e.stream, e.previous_seq, e.seq, e.utime, LogTimeS(log, e.log_utime));
  }
  if (restarts > 10) o += fmt::format("\n  restart ... and {} more", restarts - 10);
  for (size_t c = 0; c < log.gaps.size(); ++c) {
    if (log.gaps[c].gaps == 0) continue;
    // The first gap's log time: its event in the continuity.
    double first_gap_s = 0.0;
    for (const SeqEvent& e : log.continuity.events()) {
      if (e.stream == log.channel_names[c] && e.missing > 0) {
        first_gap_s = LogTimeS(log, e.log_utime);
        break;
      }
    }
    o += fmt::format(
        "\n  log gap {}: {} messages published but not in the log ({} burst(s), the first after "
        "utime {}, log +{:.3f} s)",
        log.channel_names[c], log.gaps[c].missing, log.gaps[c].gaps, log.gaps[c].intact_until_utime,
        first_gap_s);
  }
  if (restarts > 0) {
    o += fmt::format(
        "\n  A process restarted during the run: the live processes started over at the restart, "
        "the replay's did not; outputs compared after the first restart ({}) are attributed to "
        "it below (and still counted).",
        DescribeRestart(log, *FirstRestart(log)));
  } else if (log.continuity.missing() == 0) {
    o += "\n  every stream complete: no seq gap, no restart";
  }
  o += fmt::format("\n  config  {}\n", report.config_path);
  if (!report.scenario_path.empty()) o += fmt::format("  scenario {}\n", report.scenario_path);

  if (report.safety) {
    const SafetyReplayResult& s = *report.safety;
    o += fmt::format(
        "\nSafety filter: variant {}{} (from {}), force limits {}, k_position {:g}, "
        "k_velocity {:g}; live filter: {}{}\n",
        ToString(s.variant), s.qp_solver.empty() ? "" : " [" + s.qp_solver + "]",
        report.variant_source, s.force_limits ? "on" : "off", s.k_position, s.k_velocity,
        s.recorded_variant ? ToString(*s.recorded_variant) : "no diagnostics",
        s.recorded_force_limits && *s.recorded_force_limits ? ", force limits on" : "");
    o += fmt::format(
        "  inputs                {} estimates, {} nominal commands ({} without an estimate)\n",
        s.states, s.nominal_commands, s.without_state);
    o += fmt::format("  safe commands         {} replayed, {} recorded\n", s.commands.replayed,
                     s.commands.recorded);
    o += fmt::format("  filter commands       {}; {}; flags differ {}, diagnostics differ {}\n",
                     Identical(s.filter), Worst(s.filter, "N"), s.flags_differ,
                     s.diagnostics_differ);
    o += fmt::format(
        "  answered by fallback  {} nominal commands (the live process sent a fallback; "
        "compared below)\n",
        s.answered_by_fallback);
    o += fmt::format(
        "  fallback commands     {} recorded: {} stale input, {} invalid state, {} supervisor "
        "stop, {} filter last resort, {} not replayable; {}; {}\n",
        s.fallback_commands, s.fallback_stale_input, s.fallback_invalid_state,
        s.fallback_supervisor_stop, s.fallback_by_filter, s.fallback_without_input,
        Identical(s.fallback), Worst(s.fallback, "N"));
    if (!s.node_faults_from_record) {
      o += "  node faults           no supervisor announcements in the log: heartbeat faults "
           "judged on the logger's receive times, stalls and the dead-man not replayed\n";
    }
    for (const RecordedNodeFault& f : s.node_faults) {
      o += fmt::format("  node fault            after sample {:.6f} s: {}{}\n",
                       static_cast<double>(f.after_sample_utime) * 1e-6, f.reason,
                       f.unnamed > 0 ? fmt::format(" (and {} the log does not name)", f.unnamed)
                                     : std::string());
    }
    if (s.log_gap > 0) {
      o += fmt::format(
          "  log gap               {} watchdog fallbacks of the replay where the log lacks "
          "nominal commands the live process had: not compared\n",
          s.log_gap);
    }
    o += Unmatched(s.commands);
    o += fmt::format("  filter time per step  replay {} | live {} ({} steps)\n", Us(s.replayed_ns),
                     Us(s.recorded_ns), s.replayed_ns.count);
    o += "  replayed cases       ";
    for (size_t i = 0; i < 6; ++i) {
      if (s.replayed_cases[i]) {
        o += fmt::format(" {} {}", safety::kFilterCaseNames.entries[i].second, s.replayed_cases[i]);
      }
    }
    o += "\n";
  }
  if (report.controller) {
    const ControllerReplayResult& c = *report.controller;
    o += fmt::format("\nController: scenario '{}', clock from utime {}{}\n", c.scenario,
                     c.time_origin_utime,
                     c.time_origin_inferred ? " (inferred: the log lacks the first command)" : "");
    o += fmt::format(
        "  states                {} ({} not valid: skipped, {} rejected by the controller)\n",
        c.states, c.invalid_states, c.step_rejected);
    o += fmt::format("  nominal commands      {} replayed, {} recorded; {}; {}; flags differ {}\n",
                     c.commands.replayed, c.commands.recorded, Identical(c.nominal),
                     Worst(c.nominal, "N"), c.flags_differ);
    o += Unmatched(c.commands);
  }
  if (report.estimator) {
    const EstimatorReplayResult& e = *report.estimator;
    o += fmt::format("\nEstimator{}\n",
                     e.perfect_state ? " (perfect state: truth republished)" : "");
    o += fmt::format("  inputs                {} sensor samples, {} safe commands ({} rejected)\n",
                     e.sensor_samples, e.commands, e.rejected_commands);
    o += fmt::format(
        "  estimates             {} replayed, {} recorded; {}; max |dq| {:.3g}, max |dqd| {:.3g}, "
        "status differs {}\n",
        e.estimates.replayed, e.estimates.recorded, Identical(e.state.values),
        e.state.max_abs_diff_q, e.state.max_abs_diff_qd, e.status_differ);
    o += Unmatched(e.estimates);
    if (e.inputs_missing > 0) {
      o += fmt::format(
          "  after the log gap     {} inputs missing from the log after utime {}: the {} later "
          "estimates are not comparable (not counted above): {} bit-identical, max |dq| {:.3g}, "
          "max |dqd| {:.3g}, max {:.3g} sigma\n",
          e.inputs_missing, e.inputs_intact_until_utime, e.after_gap.values.compared,
          e.after_gap.values.identical, e.after_gap.max_abs_diff_q, e.after_gap.max_abs_diff_qd,
          e.after_gap.max_diff_sigma);
    }
  }
  const long differing = report.Differing();
  if (differing == 0) {
    o += fmt::format("\nResult: all {} compared outputs are bit-identical to the recorded ones.\n",
                     report.Compared());
  } else {
    o += fmt::format("\nResult: {} of {} compared outputs differ from the recorded ones", differing,
                     report.Compared());
    if (const SeqEvent* restart = FirstRestart(log)) {
      o += fmt::format(
          "; {} of them after the restart of {}: a process started over live, the replay did "
          "not",
          report.DifferingAfterRestart(), DescribeRestart(log, *restart));
    }
    o += ".\n";
  }
  return o;
}

void WriteSafetyStepsCsv(const SafetyReplayResult& safety, std::ostream& out) {
  out << "sample_utime_us,kind,replayed_flags,recorded_flags,replayed_case,replayed_ns,"
         "recorded_ns";
  for (int i = 0; i < 6; ++i) out << ",f_replayed" << i << "_n";
  for (int i = 0; i < 6; ++i) out << ",f_recorded" << i << "_n";
  out << '\n' << std::setprecision(17);
  for (const SafetyStep& step : safety.steps) {
    out << step.sample_utime << ',' << kSafetyStepKindNames.Name(step.kind) << ','
        << step.replayed_flags << ',' << step.recorded_flags << ','
        << static_cast<int>(step.replayed_case) << ',' << step.replayed_ns << ','
        << step.recorded_ns;
    for (double f : step.f_replayed) out << ',' << f;
    for (double f : step.f_recorded) out << ',' << f;
    out << '\n';
  }
}

}  // namespace stewart::replay
