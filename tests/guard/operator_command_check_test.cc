// OperatorCommandCheck: which operator RESETs an actuator believes.
#include "stewart/guard/operator_command_check.h"

#include <gtest/gtest.h>

namespace stewart {
namespace {

constexpr int64_t kNow = 1'700'000'000'000'000;

TEST(OperatorCommandCheck, AcceptsAuthenticRecentNewerCommands) {
  OperatorCommandCheck c(2'000'000);
  EXPECT_EQ(c.Check(7, 1, kNow - 1'999'999, true, kNow), OperatorVerdict::kAccepted);
  EXPECT_EQ(c.Check(7, 2, kNow + 1'000'000, true, kNow), OperatorVerdict::kAccepted);
  EXPECT_EQ(c.Check(8, 1, kNow, true, kNow), OperatorVerdict::kAccepted);  // another console
}

TEST(OperatorCommandCheck, EveryRejectionReason) {
  OperatorCommandCheck c(2'000'000);
  EXPECT_EQ(c.Check(7, 1, kNow, false, kNow), OperatorVerdict::kUnauthentic);
  EXPECT_EQ(c.Check(0, 1, kNow, true, kNow), OperatorVerdict::kZeroOperator);
  EXPECT_EQ(c.Check(7, 1, kNow - 2'000'001, true, kNow), OperatorVerdict::kStale);
  EXPECT_EQ(c.Check(7, 1, kNow + 2'000'001, true, kNow), OperatorVerdict::kStale);
  ASSERT_EQ(c.Check(7, 5, kNow, true, kNow), OperatorVerdict::kAccepted);
  // A replay of it (a log played back within the age window).
  EXPECT_EQ(c.Check(7, 5, kNow, true, kNow + 10), OperatorVerdict::kSeqNotIncreasing);
  EXPECT_EQ(c.Check(7, 4, kNow, true, kNow + 10), OperatorVerdict::kSeqNotIncreasing);
  EXPECT_STREQ(ToString(OperatorVerdict::kStale), "operator_stale");
}

TEST(OperatorCommandCheck, RemembersTheLastConsoles) {
  OperatorCommandCheck c(2'000'000);
  for (int64_t id = 1; id <= OperatorCommandCheck::kConsoles; ++id) {
    ASSERT_EQ(c.Check(id, 10, kNow, true, kNow), OperatorVerdict::kAccepted);
  }
  for (int64_t id = 1; id <= OperatorCommandCheck::kConsoles; ++id) {
    EXPECT_EQ(c.Check(id, 10, kNow, true, kNow), OperatorVerdict::kSeqNotIncreasing);
  }
  EXPECT_THROW(OperatorCommandCheck{0}, std::logic_error);
}

}  // namespace
}  // namespace stewart
