// The supervisor arms a platform resting outside a position limit that a
// recovery barrier steers back from (a start in the joint tolerance's band
// of a limit), and the filter then drives it back in; it refuses a platform
// moving faster than a velocity limit. Refused, the resting platform stayed
// with its drive off, and lead screws its load back-drove let it creep
// through the limit (the P-16P campaigns' random runs 133 and 487).
#include <gtest/gtest.h>

#include <string>

#include "safety_test_support.h"
#include "stewart/common/health_counters.h"
#include "stewart/common/signals.h"
#include "stewart/model/dynamics.h"
#include "stewart/safety/safety_process.h"

namespace stewart::safety::test {
namespace {

double LimitOf(const SafetyProcess& process, const std::string& name) {
  for (const PositionBarrierSpec& s : process.filter().constraints().position) {
    if (s.name == name) return s.limit;
  }
  ADD_FAILURE() << "no position barrier " << name;
  return 0.0;
}

struct Outcome {
  SupervisorState state;
  int32_t command_flags;
  Vector6d force_n;
};

// Steps `samples` states at (q, qd), each with a nominal command that pushes
// further out along +x, and returns the last answer.
Outcome RunAt(SafetyProcess* process, const Vector6d& q, const Vector6d& qd, int samples) {
  const Vector6d f_des = HoverForce(q) + 5.0 * Vector6d::Ones();
  SafetyOutput out;
  for (int k = 0; k < samples; ++k) {
    StateSample state;
    state.utime = state.sample_utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    state.seq = k;
    state.q = q;
    state.qd = qd;
    state.status = kStateValid;
    ForceCommand nominal;
    nominal.utime = nominal.sample_utime = state.sample_utime;
    nominal.seq = k;
    nominal.force_n = f_des;
    process->OnState(state, &out);
    process->OnNominal(nominal, &out);
  }
  return {out.mode.state, out.command.flags, out.command.force_n};
}

TEST(ArmingOutside, ArmsAtRestOutsideAPositionLimitAndSteersBack) {
  const StackConfig& c = DefaultConfig();
  HealthCounters counters("arming outside test");
  SafetyProcess process(c.platform, c.safety, c.actuators, ArmedAtOnce(), nullptr, &counters);
  Vector6d q = c.home_pose;
  q(0) = LimitOf(process, "x_upper") + 2e-3;  // 2 mm beyond, at rest
  const Outcome o = RunAt(&process, q, Vector6d::Zero(), 5);
  EXPECT_EQ(o.state, SupervisorState::kArmed);
  EXPECT_EQ(o.command_flags & kCommandDriveOff, 0);
  ASSERT_TRUE(o.force_n.allFinite());
  // The answer accelerates the platform back towards the limit (-x).
  const DynamicsTerms terms = EvaluateDynamics(c.platform, q, Vector6d::Zero());
  const Vector6d qdd = terms.M.ldlt().solve(terms.H * o.force_n - terms.G);
  EXPECT_LT(qdd(0), 0.0) << qdd.transpose();
}

TEST(ArmingOutside, RefusesAPlatformFasterThanAVelocityLimit) {
  const StackConfig& c = DefaultConfig();
  HealthCounters counters("arming outside test");
  SafetyProcess process(c.platform, c.safety, c.actuators, ArmedAtOnce(), nullptr, &counters);
  Vector6d qd = Vector6d::Zero();
  qd(2) = 0.02;  // zd above its 10 mm/s limit, inside every position limit
  const Outcome o = RunAt(&process, c.home_pose, qd, 5);
  EXPECT_EQ(o.state, SupervisorState::kDisarmed);
  EXPECT_NE(o.command_flags & kCommandDriveOff, 0);
  std::string why;
  EXPECT_FALSE(process.supervisor().OnOperator(OperatorCommand::kArm, true, "", &why));
  EXPECT_NE(why.find("velocity outside its limits"), std::string::npos) << why;
}

}  // namespace
}  // namespace stewart::safety::test
