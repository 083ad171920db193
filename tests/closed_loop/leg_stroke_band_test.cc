// What a run measures of the legs (ClosedLoopSummary::leg_stroke_worst_margin_m,
// the campaign's leg_stroke_margin_m): how far inside the band the
// leg-stroke barriers keep them in (the stroke drawn in by
// safety.leg_stroke.margin_m) the plant's legs stayed. A setpoint 36 mm
// below home puts the shortest legs inside their stroke but beyond the
// band: without the filter they go there, with it the barriers stop them
// at the band.
#include <gtest/gtest.h>

#include <cstdio>

#include "stewart/config/default_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/stack/closed_loop.h"

namespace stewart {
namespace {

ClosedLoopSummary RunBelowHome(bool no_filter) {
  const StackConfig& config = DefaultStackConfig();
  ScenarioSegment down;
  down.type = SegmentType::kStep;
  down.start_s = 0.0;
  down.end_s = 8.0;
  down.q_des = config.home_pose;
  down.q_des(2) -= 0.036;
  const Scenario scenario("below-the-leg-stroke-band", 8.0, {down});
  ClosedLoopOptions options;
  options.duration_s = 8.0;
  options.no_filter = no_filter;
  const ClosedLoopSummary s = RunClosedLoop(config, scenario, options, nullptr);
  std::printf("[leg stroke band] %s: closest %.2f mm inside the band, z %.4f m at the end\n",
              no_filter ? "no filter" : "filter", s.leg_stroke_worst_margin_m * 1e3, s.q_final(2));
  return s;
}

TEST(LegStrokeBand, TheBarriersKeepTheLegsInTheBandTheRunMeasures) {
  ASSERT_TRUE(DefaultStackConfig().safety.leg_stroke.enabled);
  const ClosedLoopSummary unfiltered = RunBelowHome(true);
  ASSERT_TRUE(unfiltered.completed) << unfiltered.failure;
  EXPECT_LT(unfiltered.leg_stroke_worst_margin_m, -3e-3);  // the setpoint is 4 mm beyond
  EXPECT_EQ(unfiltered.endstop_hits, 0);                   // and still inside the stroke
  const ClosedLoopSummary filtered = RunBelowHome(false);
  ASSERT_TRUE(filtered.completed) << filtered.failure;
  EXPECT_GE(filtered.leg_stroke_worst_margin_m, 0.0);
  EXPECT_LT(filtered.leg_stroke_worst_margin_m, 1e-3);  // stopped at the band, not before
}

}  // namespace
}  // namespace stewart
