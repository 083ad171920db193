// Scenario files: the shipped ones say what their comments say; bad files
// give errors naming the key.
#include "stewart/controller/scenario.h"

#include <gtest/gtest.h>

#include <cmath>

#include "stewart/config/default_config.h"
#include "stewart/config/scenario_loader.h"

namespace stewart {
namespace {

std::string ScenarioFile(const std::string& name) {
  return std::string(STEWART_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml";
}

// NOTES.md, "Scenario (Section V.A)", written out independently of the file.
Vector6d PaperSetpoint(double t) {
  Vector6d q = Vector6d::Zero();
  q(0) = (t >= 0 && t < 10) ? 0.1 : 0.0;
  q(1) = (t >= 10 && t < 20) ? 0.1 : 0.0;
  q(2) = (t >= 20 && t < 30) ? 0.45 : (t >= 30 && t < 40) ? 0.5 : 0.4;
  return q;
}

TEST(Scenario, PaperIsExactlyTheNotes) {
  const Scenario s = LoadScenario(ScenarioFile("paper"));
  EXPECT_EQ(s.name(), "paper");
  EXPECT_DOUBLE_EQ(s.duration_s(), 40.0);
  for (int k = 0; k <= 4500; ++k) {
    const double t = 0.01 * k;
    const Setpoint sp = s.Evaluate(t);
    EXPECT_EQ(sp.q_des, PaperSetpoint(t)) << "t = " << t;
    EXPECT_TRUE(sp.qd_des.isZero()) << "t = " << t;
    EXPECT_TRUE(sp.qdd_des.isZero()) << "t = " << t;
  }
  for (double t : {9.999999, 10.0, 19.999999, 20.0, 29.999999, 30.0, 39.999999, 40.0}) {
    EXPECT_EQ(s.Evaluate(t).q_des, PaperSetpoint(t)) << "t = " << t;
  }
  EXPECT_EQ(ResolveScenarioPath("paper"), ScenarioFile("paper"));
  EXPECT_EQ(ResolveScenarioPath("./x.yaml"), "./x.yaml");
}

TEST(Scenario, ShippedScenariosStayInsideTheWorkspace) {
  for (const char* name : {"paper", "beyond-limits", "circle"}) {
    const Scenario s = LoadScenario(ScenarioFile(name));
    EXPECT_FALSE(FirstTimeOutsideWorkspace(s, DefaultStackConfig().platform, 0.005).has_value())
        << name;
  }
}

// Largest value of q_des(axis) over the scenario, sampled every 1 ms.
double MaxOverTime(const Scenario& s, int axis, bool velocity) {
  double best = -1e9;
  for (double t = 0.0; t <= s.duration_s(); t += 1e-3) {
    const Setpoint sp = s.Evaluate(t);
    best = std::max(best, velocity ? std::abs(sp.qd_des(axis)) : sp.q_des(axis));
  }
  return best;
}

TEST(Scenario, BeyondLimitsGoesPastEveryPositionLimit) {
  const Scenario s = LoadScenario(ScenarioFile("beyond-limits"));
  ASSERT_FALSE(DefaultStackConfig().safety.position_limits.empty());
  for (const PositionLimitConfig& limit : DefaultStackConfig().safety.position_limits) {
    if (limit.upper) {
      EXPECT_GT(MaxOverTime(s, limit.axis, false), *limit.upper + 0.01) << limit.axis;
    }
    if (limit.lower) {
      double lowest = 1e9;
      for (double t = 0.0; t <= s.duration_s(); t += 1e-3) {
        lowest = std::min(lowest, s.Evaluate(t).q_des(limit.axis));
      }
      EXPECT_LT(lowest, *limit.lower - 0.01) << limit.axis;
    }
  }
}

TEST(Scenario, CircleGrazesTheLimitsSmoothly) {
  const Scenario s = LoadScenario(ScenarioFile("circle"));
  const SafetyConfig& safety = DefaultStackConfig().safety;
  for (const PositionLimitConfig& limit : safety.position_limits) {
    if (!limit.upper) continue;
    const double peak = MaxOverTime(s, limit.axis, false);
    EXPECT_NEAR(peak, *limit.upper, 2e-3) << "axis " << limit.axis;
  }
  for (const VelocityLimitConfig& limit : safety.velocity_limits) {
    if (!limit.upper) continue;
    const double peak = MaxOverTime(s, limit.axis, true);
    EXPECT_LE(peak, *limit.upper) << "axis " << limit.axis;
    EXPECT_GT(peak, 0.9 * *limit.upper) << "axis " << limit.axis;
  }
  // q_des is continuous and qd_des, qdd_des are its derivatives.
  const double h = 1e-4;
  for (double t = h; t < s.duration_s() - h; t += 0.01) {
    const Setpoint a = s.Evaluate(t - h), b = s.Evaluate(t), c = s.Evaluate(t + h);
    EXPECT_LT((c.q_des - a.q_des).norm(), 0.02 * 2 * h + 1e-12) << "t = " << t;
    bool near_boundary = false;
    for (const ScenarioSegment& seg : s.segments()) {
      near_boundary |= std::abs(t - seg.start_s) <= h;
    }
    if (near_boundary) continue;
    EXPECT_LT(((c.q_des - a.q_des) / (2 * h) - b.qd_des).norm(), 1e-7) << "t = " << t;
    EXPECT_LT(((c.qd_des - a.qd_des) / (2 * h) - b.qdd_des).norm(), 1e-6) << "t = " << t;
  }
  // It starts and ends at home, at rest.
  EXPECT_LT((s.Evaluate(0).q_des - DefaultStackConfig().home_pose).norm(), 1e-12);
  EXPECT_LT((s.Evaluate(s.duration_s()).q_des - DefaultStackConfig().home_pose).norm(), 1e-12);
  EXPECT_TRUE(s.Evaluate(s.duration_s()).qd_des.isZero());
}

struct BadCase {
  std::string yaml;
  std::string key;
};

TEST(Scenario, BadFilesNameTheKey) {
  const char* ok_segment = "{start_s: 0, type: step, q_des: [0, 0, 0.4, 0, 0, 0]}";
  const std::vector<BadCase> cases = {
      {"duration_s: 1\nsegments: []", "name"},
      {"name: a\nsegments: [{start_s: 0, type: step, q_des: [0,0,0.4,0,0,0]}]", "duration_s"},
      {"name: a\nduration_s: -1\nsegments: []", "duration_s"},
      {"name: a\nduration_s: 1", "segments"},
      {"name: a\nduration_s: 1\nsegments: []", "segments"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0, type: step, q_des: [0, 0, 0.4]}]",
       "segments[0].q_des"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0, type: step, q_des: [0,0,x,0,0,0]}]",
       "segments[0].q_des[2]"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0, type: jump, q_des: [0,0,0.4,0,0,0]}]",
       "segments[0].type"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0.5, type: step, q_des: [0,0,0.4,0,0,0]}]",
       "segments[0].start_s"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0, type: step, qdes: [0,0,0.4,0,0,0]}]",
       "segments[0].qdes"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0, type: move, q_des: [0,0,0.4,0,0,0]}]",
       "segments[0].q_from"},
      {std::string("name: a\nduration_s: 1\nsegments: [") + ok_segment + ", " + ok_segment + "]",
       "segments[1].start_s"},
      {"name: a\nduration_s: 1\nsegments: [{start_s: 0, type: sine, center: [0,0,0.4,0,0,0], "
       "amplitude: [0,0,0,0,0,0], period_s: 0}]",
       "segments[0].period_s"},
      {"name: a\nduration_s: 1\nduraton_s: 2\nsegments: []", "duraton_s"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.yaml);
    try {
      ParseScenario(c.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), std::string("bad.yaml: ") + c.key) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
    }
  }
  EXPECT_THROW(LoadScenario("/nonexistent/scenario.yaml"), ConfigError);
  EXPECT_THROW(ParseScenario("name: [unclosed"), ConfigError);
}

}  // namespace
}  // namespace stewart
