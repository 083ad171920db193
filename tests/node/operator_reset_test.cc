// What acknowledges a latched fault: an operator's RESET whose tag verifies,
// whose time is the receiver's wall clock within the window and whose seq
// is new for its operator; nothing else on the operator channel.
#include "stewart/node/operator_reset.h"

#include <gtest/gtest.h>

#include <vector>

#include "stewart/test_support/test_clock.h"
#include "stewart/test_support/test_key.h"

namespace stewart {
namespace {

using ::stewart::test::kWallUs;

using ::stewart::test::TestKey;

operator_command_t Reset(int64_t operator_id, int64_t seq, int64_t utime) {
  operator_command_t o{};
  o.utime = utime;
  o.seq = seq;
  o.operator_id = operator_id;
  o.command = operator_command_t::COMMAND_RESET;
  o.note = "test";
  return o;
}

TEST(OperatorResetFilter, SignedFreshResetIsAccepted) {
  MessageAuthenticator signer(TestKey(1));
  OperatorResetFilter filter(MessageAuthenticator(TestKey(1)), 1.0);
  operator_command_t reset = Reset(42, 1, kWallUs);
  signer.Sign(&reset);
  EXPECT_TRUE(filter.OnCommand(reset, kWallUs + 2000));
  EXPECT_EQ(filter.counts().accepted, 1);
}

TEST(OperatorResetFilter, RejectsWhatCouldNotBeTheOperatorsFreshReset) {
  MessageAuthenticator signer(TestKey(1));
  OperatorResetFilter filter(MessageAuthenticator(TestKey(1)), 1.0);

  operator_command_t wrong_key = Reset(42, 1, kWallUs);
  MessageAuthenticator(TestKey(2)).Sign(&wrong_key);
  EXPECT_FALSE(filter.OnCommand(wrong_key, kWallUs));
  EXPECT_EQ(filter.counts().rejected_auth, 1);

  operator_command_t old = Reset(42, 2, kWallUs - 5'000'000);  // 5 s old
  signer.Sign(&old);
  EXPECT_FALSE(filter.OnCommand(old, kWallUs));
  operator_command_t ahead = Reset(42, 3, kWallUs + 5'000'000);
  signer.Sign(&ahead);
  EXPECT_FALSE(filter.OnCommand(ahead, kWallUs));
  EXPECT_EQ(filter.counts().rejected_time, 2);

  operator_command_t fresh = Reset(42, 10, kWallUs);
  signer.Sign(&fresh);
  EXPECT_TRUE(filter.OnCommand(fresh, kWallUs));
  EXPECT_FALSE(filter.OnCommand(fresh, kWallUs + 1000));  // played back
  operator_command_t older_seq = Reset(42, 9, kWallUs);
  signer.Sign(&older_seq);
  EXPECT_FALSE(filter.OnCommand(older_seq, kWallUs + 1000));
  EXPECT_EQ(filter.counts().rejected_replay, 2);

  operator_command_t no_operator = Reset(0, 1, kWallUs);
  signer.Sign(&no_operator);
  EXPECT_FALSE(filter.OnCommand(no_operator, kWallUs));
  EXPECT_EQ(filter.counts().rejected_invalid, 1);

  // Another operator's seq is its own.
  operator_command_t other = Reset(43, 1, kWallUs);
  signer.Sign(&other);
  EXPECT_TRUE(filter.OnCommand(other, kWallUs));
  EXPECT_EQ(filter.counts().accepted, 2);
}

TEST(OperatorResetFilter, OnlyResetAcknowledges) {
  MessageAuthenticator signer(TestKey(1));
  OperatorResetFilter filter(MessageAuthenticator(TestKey(1)), 1.0);
  for (const int8_t command :
       {operator_command_t::COMMAND_ARM, operator_command_t::COMMAND_HOLD,
        operator_command_t::COMMAND_RESUME, operator_command_t::COMMAND_ESTOP,
        operator_command_t::COMMAND_HEARTBEAT}) {
    operator_command_t o = Reset(42, command, kWallUs);
    o.command = command;
    signer.Sign(&o);
    EXPECT_FALSE(filter.OnCommand(o, kWallUs)) << int{command};
  }
  EXPECT_EQ(filter.counts().accepted, 0);
  EXPECT_EQ(filter.counts().rejected_auth + filter.counts().rejected_time +
                filter.counts().rejected_replay,
            0);
}

TEST(OperatorResetFilter, WithoutAKeyEveryTagVerifies) {
  OperatorResetFilter filter(MessageAuthenticator(), 1.0);
  EXPECT_TRUE(filter.OnCommand(Reset(42, 1, kWallUs), kWallUs));
}

}  // namespace
}  // namespace stewart
