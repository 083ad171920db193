// The actuator guard's shipped limits (config `guard:`, guard/actuator_guard.h)
// against the shipped scenarios, in process, with the ideal legs and with the
// P-16P legs. The guard is fed what it sees in plant_sim and hw_bridge: every
// tick's leg lengths (here from ground truth, without the pots' noise, which
// the margins below cover) and every applied force.
//
// The paper and beyond-limits scenarios must never trip it and must keep a
// margin to every limit. Random setpoint sequences (the campaign's `random`)
// must never trip it on speed or force; they may trip it on a stroke margin
// only in a run whose leg really came that close to its mechanical end (the
// stack does not keep the legs in their stroke unless safety.leg_stroke is
// enabled: in 200 such runs 4 reached an end stop).
//
// STEWART_GUARD_RANDOM_RUNS=N runs N random sequences instead of the default.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/guard/actuator_guard.h"
#include "stewart/guard/guard_limits.h"
#include "stewart/model/kinematics.h"
#include "stewart/stack/campaign.h"

namespace stewart {
namespace {

/// What the guard saw over one or many runs.
struct Seen {
  double min_end_distance_m = 1e9;
  double max_speed_mps = 0.0;
  double max_force_n = 0.0;
  long runs = 0;
  long stroke_trip_runs = 0;  ///< runs in which a leg came within the margin of its end
  long other_trips = 0;       ///< speed, force or reading trips: never expected
  std::string first_other_trip;
};

/// Feeds one run's per-tick CSV (closed_loop.h's columns: t, q_*, qd_*,
/// qest_*, qdest_*, fdes_*, fsafe_*, ...) to a guard; after a trip it goes
/// on with a fresh one, as if an operator had cleared it, to see the rest.
void FeedRun(const StackConfig& config, const std::string& csv, const std::string& what,
             Seen* seen) {
  const ActuatorGuardLimits limits = ActuatorGuardLimitsOf(
      config.guard, config.platform.leg_min_length_m, config.platform.leg_max_length_m);
  ActuatorGuard guard(limits);
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  constexpr std::size_t kFsafe = 1 + 4 * 6 + 6;
  std::vector<double> v;
  bool stroke_trip = false;
  const auto take_figures = [&] {
    seen->min_end_distance_m = std::min(seen->min_end_distance_m, guard.min_end_distance_m());
    seen->max_speed_mps = std::max(seen->max_speed_mps, guard.max_speed_mps());
    seen->max_force_n = std::max(seen->max_force_n, guard.max_force_n());
  };
  while (std::getline(in, line)) {
    v.clear();
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) v.push_back(std::strtod(field.c_str(), nullptr));
    ASSERT_GE(v.size(), kFsafe + 6);
    Vector6d q, f;
    for (std::size_t i = 0; i < 6; ++i) {
      q(static_cast<int>(i)) = v[1 + i];
      f(static_cast<int>(i)) = v[kFsafe + i];
    }
    const auto utime = static_cast<int64_t>(std::llround(v[0] * 1e6));
    guard.OnReadings(utime, InverseKinematics(config.platform, q));
    guard.OnForceCommand(f);
    if (!guard.tripped()) continue;
    const GuardTripReason r = guard.trip().reason;
    if (r == GuardTripReason::kRetractedEnd || r == GuardTripReason::kExtendedEnd) {
      stroke_trip = true;
    } else {
      ++seen->other_trips;
      if (seen->first_other_trip.empty()) {
        seen->first_other_trip =
            what + " at t = " + std::to_string(v[0]) + " s: " + guard.Describe();
      }
    }
    take_figures();
    guard = ActuatorGuard(limits);
  }
  take_figures();
  seen->stroke_trip_runs += stroke_trip ? 1 : 0;
  ++seen->runs;
}

/// The config with `overlays` merged, as a file the campaign can load.
std::string MergedConfigFile(const std::vector<std::string>& overlays) {
  if (overlays.empty()) return DefaultConfigPath();
  const std::string path =
      ::testing::TempDir() + "/guard_margins_" + std::to_string(getpid()) + ".yaml";
  YAML::Emitter out;
  out << LoadMergedConfigYaml(DefaultConfigPath(), overlays);
  std::ofstream(path) << out.c_str();
  return path;
}

Seen Campaign(const std::string& scenario, const std::vector<std::string>& overlays, long runs) {
  const CampaignSpec spec = MakeCampaignSpec(MergedConfigFile(overlays), scenario, "", 11, 0.0);
  Seen seen;
  for (long i = 0; i < runs; ++i) {
    std::ostringstream csv;
    const CampaignRow row = RunCampaignRow(spec, i, &csv);
    EXPECT_TRUE(row.summary.failure.empty()) << row.summary.failure;
    FeedRun(spec.config, csv.str(), scenario + " run " + std::to_string(i), &seen);
  }
  return seen;
}

void Print(const GuardConfig& g, const Seen& s, const std::string& what) {
  std::printf(
      "[guard margins] %s, %ld runs: closest leg to a stroke end %.1f mm (guard %.1f mm, "
      "tripped in %ld runs), fastest leg %.1f mm/s (cap %.1f), largest force %.2f N "
      "(bound %.1f), other trips %ld\n",
      what.c_str(), s.runs, s.min_end_distance_m * 1e3, g.leg_stroke_margin_m * 1e3,
      s.stroke_trip_runs, s.max_speed_mps * 1e3, g.leg_speed_cap_mps * 1e3, s.max_force_n,
      g.leg_force_limit_n, s.other_trips);
}

/// Never tripped, with room for the pots' noise (0.05 mm, a 0.2 mm ADC step;
/// ~3 mm/s on the speed estimate) on top of ground truth.
void ExpectNeverTripped(const GuardConfig& g, const Seen& s, const std::string& what) {
  Print(g, s, what);
  EXPECT_EQ(s.other_trips, 0) << s.first_other_trip;
  EXPECT_EQ(s.stroke_trip_runs, 0);
  EXPECT_GT(s.min_end_distance_m, g.leg_stroke_margin_m + 0.001);
  EXPECT_LT(s.max_speed_mps, g.leg_speed_cap_mps - 0.005);
  EXPECT_LT(s.max_force_n, g.leg_force_limit_n);
}

/// Random sequences: never on speed or force; on a stroke margin only where
/// a leg truly came that close to its end (FeedRun counts it from ground
/// truth), in a few runs.
void ExpectOnlyDeservedTrips(const GuardConfig& g, const Seen& s, const std::string& what) {
  Print(g, s, what);
  EXPECT_EQ(s.other_trips, 0) << s.first_other_trip;
  EXPECT_LE(s.stroke_trip_runs, s.runs / 10 + 1);
  EXPECT_LT(s.max_speed_mps, g.leg_speed_cap_mps - 0.005);
  EXPECT_LT(s.max_force_n, g.leg_force_limit_n);
}

long RandomRuns() {
  const char* env = std::getenv("STEWART_GUARD_RANDOM_RUNS");
  return env != nullptr ? std::atol(env) : 10;
}

TEST(GuardMargins, IdealLegsShippedScenarios) {
  const GuardConfig& g = DefaultStackConfig().guard;
  ExpectNeverTripped(g, Campaign("paper", {}, 1), "ideal legs, paper");
  ExpectNeverTripped(g, Campaign("beyond-limits", {}, 1), "ideal legs, beyond-limits");
  ExpectOnlyDeservedTrips(g, Campaign("random", {}, RandomRuns()), "ideal legs, random");
}

TEST(GuardMargins, P16pLegsShippedScenarios) {
  const GuardConfig& g = DcMotorStackConfig().guard;
  ExpectNeverTripped(g, Campaign("paper", {DcMotorOverlayPath()}, 1), "P-16P legs, paper");
  ExpectNeverTripped(g, Campaign("beyond-limits", {DcMotorOverlayPath()}, 1),
                     "P-16P legs, beyond-limits");
  ExpectOnlyDeservedTrips(g, Campaign("random", {DcMotorOverlayPath()}, RandomRuns()),
                          "P-16P legs, random");
}

}  // namespace
}  // namespace stewart
