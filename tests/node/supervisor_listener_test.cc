// The console's wait for the supervisor's answer: every state a receive
// drains is judged, so an answer followed at once by a state that names
// another operator (a dead-man console's heartbeat) is still found; states
// with a bad MAC never answer. LCM port 7808 (this test's own).
#include "stewart/node/supervisor_listener.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "stewart/node/lcm_handle.h"

namespace stewart {
namespace {

constexpr int kListenerPort = 7808;
constexpr char kListenerChannel[] = "TEST_SUPERVISOR";

supervisor_state_t State(int64_t operator_id, int64_t operator_seq, int64_t seq) {
  supervisor_state_t s{};
  s.seq = seq;
  s.state = supervisor_state_t::STATE_ARMING;
  s.last_operator_id = operator_id;
  s.last_operator_seq = operator_seq;
  return s;
}

TEST(SupervisorListener, FindsTheAnswerWhenAnotherOperatorsStateFollowsItInOneBatch) {
  MessageAuthenticator auth;
  SupervisorListener listener(PrivateLcmUrl(kListenerPort), kListenerChannel, &auth);
  auto lcm = MakeLcm(PrivateLcmUrl(kListenerPort));
  // The answer to (id 42, seq 1), then the state after a heartbeat from
  // console 7, both queued before the wait reads the socket.
  const supervisor_state_t answer = State(42, 1, 10);
  const supervisor_state_t after_heartbeat = State(7, 30, 11);
  lcm->publish(kListenerChannel, &answer);
  lcm->publish(kListenerChannel, &after_heartbeat);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const auto is_reply = [](const supervisor_state_t& s) {
    return s.last_operator_id == 42 && s.last_operator_seq == 1;
  };
  ASSERT_TRUE(listener.WaitFor(2.0, is_reply));
  EXPECT_EQ(listener.matched().seq, 10);
  // Everything the batch held was received; the newest names console 7.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (listener.received() < 2 && std::chrono::steady_clock::now() < deadline) {
    listener.WaitFor(0.05, [](const supervisor_state_t&) { return false; });
  }
  EXPECT_EQ(listener.received(), 2);
  EXPECT_EQ(listener.latest().last_operator_id, 7);
}

TEST(SupervisorListener, TimesOutWithoutAnAnswerAndDropsForgedStates) {
  MessageAuthenticator keyed(std::vector<uint8_t>(32, 0x5a));
  SupervisorListener listener(PrivateLcmUrl(kListenerPort), kListenerChannel, &keyed);
  auto lcm = MakeLcm(PrivateLcmUrl(kListenerPort));
  supervisor_state_t forged = State(42, 1, 12);  // unsigned: its tag cannot verify
  lcm->publish(kListenerChannel, &forged);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(
      listener.WaitFor(0.3, [](const supervisor_state_t& s) { return s.last_operator_id == 42; }));
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(290));
  EXPECT_EQ(listener.forged(), 1);
  EXPECT_EQ(listener.received(), 0);
  // The same state signed answers.
  supervisor_state_t signed_state = State(42, 1, 13);
  keyed.Sign(&signed_state);
  lcm->publish(kListenerChannel, &signed_state);
  ASSERT_TRUE(
      listener.WaitFor(2.0, [](const supervisor_state_t& s) { return s.last_operator_id == 42; }));
  EXPECT_EQ(listener.matched().seq, 13);
}

}  // namespace
}  // namespace stewart
