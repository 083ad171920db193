#include "stewart/test_support/recorded_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <optional>

#include "stewart/model/types.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {

std::vector<Bound> BoundsOf(const SafetyConfig& safety) {
  std::vector<Bound> bounds;
  auto add = [&bounds](const std::string& kind, bool velocity, int axis,
                       const std::optional<double>& lower, const std::optional<double>& upper) {
    const std::string prefix = kind + " " + std::string(kAxisNames[axis]);
    if (upper) {
      bounds.push_back({prefix + " <= " + FormatNumber(*upper), velocity, axis, 1.0, *upper});
    }
    if (lower) {
      bounds.push_back({prefix + " >= " + FormatNumber(*lower), velocity, axis, -1.0, *lower});
    }
  };
  for (const PositionLimitConfig& p : safety.position_limits) {
    add("position", false, p.axis, p.lower, p.upper);
  }
  for (const VelocityLimitConfig& v : safety.velocity_limits) {
    add("velocity", true, v.axis, v.lower, v.upper);
  }
  return bounds;
}

const Bound* RecordedRun::Worst() const {
  const Bound* worst = nullptr;
  for (const Bound& b : bounds) {
    if (worst == nullptr || b.max_excess > worst->max_excess) worst = &b;
  }
  return worst;
}

void AddTruthSample(const state_t& state, RecordedRun* run) {
  RecordedRun& s = *run;
  bool finite = true;
  for (int i = 0; i < 6; ++i) {
    finite = finite && std::isfinite(state.q[i]) && std::isfinite(state.qd[i]);
  }
  if (!finite) {
    ++s.truth_non_finite;
    return;
  }
  if (s.truth_samples == 0) s.first_truth = state;
  const double t_s = static_cast<double>(state.utime - s.first_truth.utime) * 1e-6;
  s.truth_span_s = t_s;
  ++s.truth_samples;
  s.max_x = std::max(s.max_x, state.q[0]);
  s.max_xd = std::max(s.max_xd, state.qd[0]);
  for (Bound& b : s.bounds) {
    const double value = b.velocity ? state.qd[b.axis] : state.q[b.axis];
    const double excess = b.sign * (value - b.bound);
    if (excess > b.max_excess) {
      b.max_excess = excess;
      b.at_s = t_s;
      b.value_at_max = value;
    }
  }
}

RecordedRun ReadRecordedRun(const std::string& log_path, const StackConfig& config) {
  RecordedRun s;
  s.bounds = BoundsOf(config.safety);
  lcm::LogFile log(log_path, "r");
  if (!log.good()) return s;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    const bool truth_channel = event->channel == config.lcm.channels.state_truth;
    const bool estimate_channel = event->channel == config.lcm.channels.state_estimate;
    if (!truth_channel && !estimate_channel) continue;
    state_t state{};
    const bool decoded = state.decode(event->data, 0, event->datalen) == event->datalen;
    if (estimate_channel) {
      if (!decoded) {
        ++s.estimates_undecodable;
        continue;
      }
      ++s.estimates;
      if ((state.status & state_t::STATUS_DIVERGED) != 0) ++s.diverged_estimates;
      continue;
    }
    if (!decoded) {
      ++s.truth_undecodable;
      continue;
    }
    AddTruthSample(state, &s);
  }
  return s;
}

std::string Describe(const RecordedRun& run) {
  const Bound* worst = run.Worst();
  char text[256];
  std::snprintf(
      text, sizeof text,
      "%ld truth samples over %.2f s, max x %.5f m, max xd %.5f m/s, max excess %.2e (%s)",
      run.truth_samples, run.truth_span_s, run.max_x, run.max_xd, worst->max_excess,
      worst->name.c_str());
  return text;
}

void ExpectWithinLimits(const RecordedRun& run) {
  for (const Bound& b : run.bounds) {
    EXPECT_LE(b.max_excess, kLimitTolerance)
        << b.name << " exceeded by " << b.max_excess << " at t = " << b.at_s << " s (value "
        << b.value_at_max << ")";
  }
}

}  // namespace stewart::test
