// The safety process answers the same commands whatever the order in which
// a state and the nominal command derived from it arrive (multicast from two
// senders is not ordered), so an in-process run, a live run over LCM and a
// replay agree bit for bit.
#include <gtest/gtest.h>

#include <limits>
#include <optional>
#include <vector>

#include "safety_test_support.h"
#include "stewart/common/health_counters.h"
#include "stewart/safety/safety_process.h"

namespace stewart::safety::test {
namespace {

struct Answer {
  int64_t sample_utime;
  Vector6d force_n;
  int32_t flags;
  int32_t fallback_reason;  ///< 0: the nominal command was filtered (fresh)
  SupervisorState state;
};

// Steps `samples` states from start-up, each with its nominal command, in
// the order given per sample (true: nominal first), and returns every answer.
std::vector<Answer> Answers(const std::vector<bool>& nominal_first) {
  const StackConfig& c = DefaultConfig();
  HealthCounters counters("safety order test");
  SafetyProcess process(c.platform, c.safety, c.actuators, ArmedAtOnce(), nullptr, &counters);
  const Vector6d q = c.home_pose;
  const Vector6d f_des = HoverForce(q) + Vector6d::Constant(0.5);
  std::vector<Answer> answers;
  for (size_t k = 0; k < nominal_first.size(); ++k) {
    StateSample state;
    state.utime = state.sample_utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    state.seq = static_cast<int64_t>(k);
    state.q = q;
    state.status = kStateValid;
    ForceCommand nominal;
    nominal.utime = nominal.sample_utime = state.sample_utime;
    nominal.seq = static_cast<int64_t>(k);
    nominal.force_n = f_des;
    SafetyOutput out;
    const auto keep = [&](bool answered) {
      if (answered)
        answers.push_back({out.command.sample_utime, out.command.force_n, out.command.flags,
                           out.fallback_reason, out.mode.state});
    };
    if (nominal_first[k]) {
      keep(process.OnNominal(nominal, &out));
      keep(process.OnState(state, &out));
    } else {
      keep(process.OnState(state, &out));
      keep(process.OnNominal(nominal, &out));
    }
  }
  return answers;
}

TEST(SafetyProcessOrder, StateOrNominalFirstGiveTheSameCommands) {
  const std::vector<bool> state_first(6, false);
  const std::vector<bool> nominal_first(6, true);
  const std::vector<bool> mixed = {true, false, true, true, false, true};
  const std::vector<Answer> reference = Answers(state_first);
  ASSERT_EQ(reference.size(), 6u);  // one answer per sample
  // The first usable state gives the controller stale_age_s to answer: its
  // nominal is filtered, in every order.
  EXPECT_FALSE(reference[0].flags & kCommandFallback);
  EXPECT_FALSE(reference[1].flags & kCommandFallback);
  for (const auto& order : {nominal_first, mixed}) {
    const std::vector<Answer> answers = Answers(order);
    ASSERT_EQ(answers.size(), reference.size());
    for (size_t i = 0; i < answers.size(); ++i) {
      EXPECT_EQ(answers[i].sample_utime, reference[i].sample_utime) << i;
      EXPECT_EQ(answers[i].force_n, reference[i].force_n) << i;
      EXPECT_EQ(answers[i].flags, reference[i].flags) << i;
    }
  }
}

// After an estimator restart (states not usable for longer than the stale
// age, no nominals: the controller answers usable states only) the first
// usable state's nominal is filtered, whether the controller's answers come
// before the next state or after it: which one wins the multicast race must
// not decide between filter and fallback (it did, 1 run in 6 of the
// in-process vs LCM lockstep comparison under load).
std::vector<Answer> AnswersAcrossARestart(bool answers_late) {
  const StackConfig& c = DefaultConfig();
  HealthCounters counters("safety restart order test");
  SafetyProcess process(c.platform, c.safety, c.actuators, ArmedAtOnce(), nullptr, &counters);
  const Vector6d q = c.home_pose;
  const Vector6d f_des = HoverForce(q) + Vector6d::Constant(0.5);
  constexpr int kUsableBefore = 5, kUnusable = 30, kUsableAfter = 6;
  static_assert(kUnusable * 1000 > 20000, "longer than the shipped stale age");
  std::vector<Answer> answers;
  SafetyOutput out;
  const auto keep = [&](bool answered) {
    if (answered)
      answers.push_back({out.command.sample_utime, out.command.force_n, out.command.flags,
                         out.fallback_reason, out.mode.state});
  };
  const auto nominal_of = [&](int64_t sample_utime) {
    ForceCommand nominal;
    nominal.utime = nominal.sample_utime = sample_utime;
    nominal.force_n = f_des;
    return nominal;
  };
  bool late_nominal = false;
  int64_t late_sample_utime = 0;
  for (int k = 0; k < kUsableBefore + kUnusable + kUsableAfter; ++k) {
    StateSample state;
    state.utime = state.sample_utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    state.q = q;
    const bool usable = k < kUsableBefore || k >= kUsableBefore + kUnusable;
    state.status = usable ? kStateValid : kStateInitializing;
    keep(process.OnState(state, &out));
    if (late_nominal) {  // the answer to the previous state, overtaken by this one
      keep(process.OnNominal(nominal_of(late_sample_utime), &out));
      late_nominal = false;
    }
    if (!usable) continue;
    if (answers_late && k >= kUsableBefore + kUnusable) {
      late_nominal = true;
      late_sample_utime = state.sample_utime;
    } else {
      keep(process.OnNominal(nominal_of(state.sample_utime), &out));
    }
  }
  if (late_nominal) keep(process.OnNominal(nominal_of(late_sample_utime), &out));
  return answers;
}

TEST(SafetyProcessOrder, AfterAnEstimatorRestartLateAnswersGiveTheSameCommands) {
  const std::vector<Answer> prompt = AnswersAcrossARestart(false);
  const std::vector<Answer> late = AnswersAcrossARestart(true);
  ASSERT_EQ(prompt.size(), 41u);  // one answer per sample
  ASSERT_EQ(late.size(), prompt.size());
  for (size_t i = 0; i < prompt.size(); ++i) {
    EXPECT_EQ(late[i].sample_utime, prompt[i].sample_utime) << i;
    EXPECT_EQ(late[i].force_n, prompt[i].force_n) << i;
    EXPECT_EQ(late[i].flags, prompt[i].flags) << i;
    EXPECT_EQ(late[i].fallback_reason, prompt[i].fallback_reason) << i;
    EXPECT_EQ(late[i].state, prompt[i].state) << i;
  }
  // The unusable states got the fallback, the first usable one after them
  // its nominal filtered (fresh, not the watchdog's stale input); the
  // supervisor holds the platform after the gap until an operator resumes.
  EXPECT_EQ(prompt[4].state, SupervisorState::kArmed);
  EXPECT_TRUE(prompt[5].flags & kCommandFallback);
  EXPECT_NE(prompt[5].fallback_reason, 0);
  EXPECT_TRUE(prompt[34].flags & kCommandFallback);
  // Every unusable state, ARMED (5) then HOLD, got the actuators off with
  // zero force: a force from such a state would be open loop.
  for (int k = 5; k < 35; ++k) {
    EXPECT_EQ(prompt[k].flags & (kCommandDriveOff | kCommandInvalidInput),
              kCommandDriveOff | kCommandInvalidInput)
        << k;
    EXPECT_EQ(prompt[k].force_n, Vector6d::Zero()) << k;
  }
  EXPECT_EQ(prompt[36].flags & kCommandDriveOff, 0);
  EXPECT_EQ(prompt[35].fallback_reason, 0);
  EXPECT_EQ(prompt[36].fallback_reason, 0);
  EXPECT_EQ(prompt[36].state, SupervisorState::kHold);
}

// A lockstep resend of the state answered last (common/resend_answer.h):
// the same command again, the filter, watchdog and supervisor not stepped,
// so the answers after it are those without the resend. A NaN nominal is
// refused before it can wait for its state and displace the real one.
std::vector<Answer> AnswersWithFaults(bool live, int resend_at, int nan_nominal_at,
                                      HealthCounters* counters, int* answered_again) {
  const StackConfig& c = DefaultConfig();
  SafetyProcess process(c.platform, c.safety, c.actuators, ArmedAtOnce(), nullptr, counters);
  const Vector6d q = c.home_pose;
  const Vector6d f_des = HoverForce(q) + Vector6d::Constant(0.5);
  std::vector<Answer> answers;
  for (int k = 0; k < 8; ++k) {
    const int64_t utime = 1'000'000 + 1000 * k;
    const auto wall = [&](int64_t after_us) {
      return live ? std::optional<int64_t>(5'000'000 + utime + after_us) : std::nullopt;
    };
    StateSample state;
    state.utime = state.sample_utime = utime;
    state.seq = k;
    state.q = q;
    state.status = kStateValid;
    ForceCommand nominal;
    nominal.utime = nominal.sample_utime = utime;
    nominal.seq = k;
    nominal.force_n = f_des;
    SafetyOutput out;
    if (k == nan_nominal_at) {
      // Ahead of its state, as a nominal may overtake it on the bus.
      ForceCommand poisoned = nominal;
      poisoned.force_n(2) = std::numeric_limits<double>::quiet_NaN();
      EXPECT_FALSE(process.OnNominal(poisoned, &out, wall(0)));
    }
    if (process.OnState(state, &out, wall(0))) {
      ADD_FAILURE() << "no answer before the nominal at " << k;
    }
    EXPECT_TRUE(process.OnNominal(nominal, &out, wall(10)));
    answers.push_back({out.command.sample_utime, out.command.force_n, out.command.flags,
                       out.fallback_reason, out.mode.state});
    EXPECT_TRUE(out.diagnostics->f_des.allFinite());
    if (k != resend_at) continue;
    const SafetyOutput first = out;
    SafetyOutput again;
    if (live) {
      EXPECT_FALSE(process.OnState(state, &again, wall(1000)));
    }
    if (process.OnState(state, &again, wall(200'000))) {
      ++*answered_again;
      EXPECT_EQ(again.command.seq, first.command.seq);
      EXPECT_EQ(again.command.force_n, first.command.force_n);
      EXPECT_EQ(again.command.flags, first.command.flags);
      EXPECT_EQ(again.diagnostics->f_safe, first.diagnostics->f_safe);
    }
    // The nominal resent by the controller as well: answered once already.
    EXPECT_FALSE(process.OnNominal(nominal, &again, wall(200'010)));
  }
  return answers;
}

TEST(SafetyProcessResend, TheStateAnsweredLastIsAnsweredAgainWithoutASecondStep) {
  for (const bool live : {true, false}) {
    SCOPED_TRACE(live ? "live" : "replay");
    HealthCounters clean_counters("clean"), counters("resend");
    int unused = 0, answered = 0;
    const std::vector<Answer> reference = AnswersWithFaults(live, -1, -1, &clean_counters, &unused);
    const std::vector<Answer> resent = AnswersWithFaults(live, 4, -1, &counters, &answered);
    EXPECT_EQ(answered, 1);
    EXPECT_EQ(counters.counter("resends_answered"), 1);
    EXPECT_EQ(counters.counter("rejected_state_time_not_increasing"), live ? 1 : 0);
    ASSERT_EQ(resent.size(), reference.size());
    for (size_t k = 0; k < reference.size(); ++k) {
      EXPECT_EQ(resent[k].sample_utime, reference[k].sample_utime) << k;
      EXPECT_EQ(resent[k].force_n, reference[k].force_n) << k;
      EXPECT_EQ(resent[k].flags, reference[k].flags) << k;
      EXPECT_EQ(resent[k].state, reference[k].state) << k;
    }
  }
}

TEST(SafetyProcessResend, ANonFiniteNominalIsRefusedBeforeItWaitsForItsState) {
  HealthCounters clean_counters("clean"), counters("nan");
  int unused = 0;
  const std::vector<Answer> reference = AnswersWithFaults(true, -1, -1, &clean_counters, &unused);
  const std::vector<Answer> poisoned = AnswersWithFaults(true, -1, 3, &counters, &unused);
  EXPECT_EQ(counters.counter("rejected_nominal_non_finite"), 1);
  EXPECT_EQ(counters.counter("nominal_before_state"), 0);
  ASSERT_EQ(poisoned.size(), reference.size());
  for (size_t k = 0; k < reference.size(); ++k) {
    EXPECT_EQ(poisoned[k].force_n, reference[k].force_n) << k;
    EXPECT_EQ(poisoned[k].flags, reference[k].flags) << k;
  }
}

}  // namespace
}  // namespace stewart::safety::test
