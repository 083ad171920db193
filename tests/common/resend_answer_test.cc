// ResendAnswer: only the exact input last answered is answered again, live at
// most once per interval of receive time, always without a receive time.
#include "stewart/common/resend_answer.h"

#include <gtest/gtest.h>

namespace stewart {
namespace {

TEST(ResendAnswer, NothingAnsweredYetIsNoResend) {
  ResendAnswer rule;
  EXPECT_FALSE(rule.AnswerAgain(1000, 1, std::nullopt));
  EXPECT_FALSE(rule.AnswerAgain(1000, 1, 5'000'000));
}

TEST(ResendAnswer, OnlyTheSameUtimeAndSeqAsTheLastAnswerIsAResend) {
  ResendAnswer rule;
  rule.Answered(2000, 2, std::nullopt);
  EXPECT_FALSE(rule.AnswerAgain(2000, 3, std::nullopt)) << "another seq";
  EXPECT_FALSE(rule.AnswerAgain(1000, 2, std::nullopt)) << "another utime";
  EXPECT_FALSE(rule.AnswerAgain(1000, 1, std::nullopt)) << "an older input";
  EXPECT_TRUE(rule.AnswerAgain(2000, 2, std::nullopt));
  // A newer answer replaces it: the previous input is no longer waited on.
  rule.Answered(3000, 3, std::nullopt);
  EXPECT_FALSE(rule.AnswerAgain(2000, 2, std::nullopt));
  EXPECT_TRUE(rule.AnswerAgain(3000, 3, std::nullopt));
  rule.Clear();
  EXPECT_FALSE(rule.AnswerAgain(3000, 3, std::nullopt));
}

TEST(ResendAnswer, ANewerInputEndsTheRuleForTheAnswerBeforeIt) {
  ResendAnswer rule;
  rule.Answered(2000, 2, std::nullopt);
  // Input 3 came and got no answer (e.g. not usable): the loop moved on, a
  // copy of input 2 is only a copy.
  EXPECT_FALSE(rule.AnswerAgain(3000, 3, std::nullopt));
  EXPECT_FALSE(rule.AnswerAgain(2000, 2, std::nullopt));
}

TEST(ResendAnswer, LiveAResendIsAnsweredOncePerIntervalNotOncePerCopy) {
  ResendAnswer rule(100'000);
  rule.Answered(2000, 2, 1'000'000);
  // Copies within the interval of the answer: a duplicate flood, not a stall.
  int answered = 0;
  for (int64_t wall = 1'000'000; wall < 1'100'000; wall += 1'000) {
    answered += rule.AnswerAgain(2000, 2, wall) ? 1 : 0;
  }
  EXPECT_EQ(answered, 0);
  // plant_sim's resend, 0.2 s after the sample: answered.
  EXPECT_TRUE(rule.AnswerAgain(2000, 2, 1'200'000));
  // The interval counts from that answer again.
  EXPECT_FALSE(rule.AnswerAgain(2000, 2, 1'250'000));
  EXPECT_TRUE(rule.AnswerAgain(2000, 2, 1'400'000));
  // 1000 copies a second for a second: at most 10 answers.
  answered = 0;
  for (int64_t wall = 1'401'000; wall <= 2'400'000; wall += 1'000) {
    answered += rule.AnswerAgain(2000, 2, wall) ? 1 : 0;
  }
  EXPECT_EQ(answered, 10);
}

TEST(ResendAnswer, WithoutAReceiveTimeEveryResendIsAnswered) {
  ResendAnswer rule(100'000);
  rule.Answered(2000, 2, std::nullopt);
  EXPECT_TRUE(rule.AnswerAgain(2000, 2, std::nullopt));
  EXPECT_TRUE(rule.AnswerAgain(2000, 2, std::nullopt));
  // Answered live, asked again without a time (and the reverse): answered.
  rule.Answered(3000, 3, 1'000'000);
  EXPECT_TRUE(rule.AnswerAgain(3000, 3, std::nullopt));
  EXPECT_TRUE(rule.AnswerAgain(3000, 3, 1'000'001));
}

}  // namespace
}  // namespace stewart
