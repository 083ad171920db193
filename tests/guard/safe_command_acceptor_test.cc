// SafeCommandAcceptor: every rejection reason, session adoption and switch,
// and why a replayed log or a second stack is not followed.
#include "stewart/guard/safe_command_acceptor.h"

#include <gtest/gtest.h>

#include <limits>

#include "stewart/model/types.h"

namespace stewart {
namespace {

constexpr int64_t kA = 1111;  // the safety session the receiver follows
constexpr int64_t kB = 2222;  // another one (a second stack, a restarted safety)

const SafeCommandAcceptorLimits kLimits{};  // 50 ms, 250 ms, 300 ms, 1.5 s

ForceCommand Command(int64_t session, int64_t seq, int64_t sample_utime,
                     const Vector6d& force = Vector6d::Constant(2.0)) {
  ForceCommand c;
  c.utime = c.sample_utime = sample_utime;
  c.seq = seq;
  c.session_id = session;
  c.force_n = force;
  return c;
}

/// A receiver at sample time 10 s following session kA.
SafeCommandAcceptor Following() {
  SafeCommandAcceptor a(kLimits);
  a.OnSamplePublished(10'000'000);
  EXPECT_EQ(a.OnAnnouncement({9'999'000, 1, kA}, true, 0), AnnouncementVerdict::kAdopted);
  return a;
}

TEST(SafeCommandAcceptor, AcceptsTheAnnouncedSessionsFreshCommandsInOrder) {
  SafeCommandAcceptor a = Following();
  EXPECT_TRUE(a.has_session());
  EXPECT_EQ(a.session_id(), kA);
  EXPECT_EQ(a.Check(Command(kA, 5, 10'000'000), true), CommandRejection::kNone);
  EXPECT_EQ(a.Check(Command(kA, 6, 9'990'000), true), CommandRejection::kNone);  // 10 ms old
  // seq may jump (a lost message), time need not increase (the gate's job).
  EXPECT_EQ(a.Check(Command(kA, 60, 9'950'000), true), CommandRejection::kNone);  // exactly 50 ms
  EXPECT_EQ(a.accepted(), 3);
}

TEST(SafeCommandAcceptor, EveryRejectionReason) {
  SafeCommandAcceptor none(kLimits);
  EXPECT_EQ(none.Check(Command(kA, 1, 0), true), CommandRejection::kNoSession);
  EXPECT_EQ(none.Check(Command(kA, 1, 0), false), CommandRejection::kUnauthentic);

  SafeCommandAcceptor a = Following();
  EXPECT_EQ(a.Check(Command(kA, 1, 10'000'000), false), CommandRejection::kUnauthentic);
  EXPECT_EQ(a.Check(Command(kB, 1, 10'000'000), true), CommandRejection::kWrongSession);
  EXPECT_EQ(a.Check(Command(0, 1, 10'000'000), true), CommandRejection::kWrongSession);
  EXPECT_EQ(a.Check(Command(kA, 1, 10'000'001), true), CommandRejection::kFutureSample);
  EXPECT_EQ(a.Check(Command(kA, 1, 9'949'999), true), CommandRejection::kStaleSample);
  Vector6d nan = Vector6d::Constant(1.0);
  nan(3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(a.Check(Command(kA, 1, 10'000'000, nan), true), CommandRejection::kNonFiniteForce);
  ASSERT_EQ(a.Check(Command(kA, 7, 10'000'000), true), CommandRejection::kNone);
  EXPECT_EQ(a.Check(Command(kA, 7, 10'000'000), true), CommandRejection::kSeqNotIncreasing);
  EXPECT_EQ(a.Check(Command(kA, 3, 10'000'000), true), CommandRejection::kSeqNotIncreasing);

  const auto& n = a.command_rejections();
  EXPECT_EQ(n[kCommandRejectionNames.Index(CommandRejection::kWrongSession)], 2);
  EXPECT_EQ(n[kCommandRejectionNames.Index(CommandRejection::kSeqNotIncreasing)], 2);
  EXPECT_EQ(a.accepted(), 1);
  EXPECT_STREQ(ToString(CommandRejection::kStaleSample), "command_stale_sample");
}

// A rejected command changes nothing: a forged seq far ahead (without the
// key nothing stops its session id being right, but an unauthentic one)
// does not lock the real commands out.
TEST(SafeCommandAcceptor, RejectedCommandsDoNotAdvanceTheSeq) {
  SafeCommandAcceptor a = Following();
  EXPECT_EQ(a.Check(Command(kA, std::numeric_limits<int64_t>::max(), 10'000'000), false),
            CommandRejection::kUnauthentic);
  EXPECT_EQ(a.Check(Command(kA, 1000, 9'000'000), true), CommandRejection::kStaleSample);
  EXPECT_EQ(a.Check(Command(kA, 2, 10'000'000), true), CommandRejection::kNone);
}

TEST(SafeCommandAcceptor, NoSampleYetMeansNothingIsJudgedFresh) {
  SafeCommandAcceptor a(kLimits);
  EXPECT_EQ(a.OnAnnouncement({0, 1, kA}, true, 0), AnnouncementVerdict::kNoSample);
  EXPECT_FALSE(a.has_session());
}

TEST(SafeCommandAcceptor, AnnouncementRejections) {
  SafeCommandAcceptor a(kLimits);
  a.OnSamplePublished(10'000'000);
  EXPECT_EQ(a.OnAnnouncement({10'000'000, 1, kA}, false, 0), AnnouncementVerdict::kUnauthentic);
  EXPECT_EQ(a.OnAnnouncement({10'000'000, 1, 0}, true, 0), AnnouncementVerdict::kZeroSession);
  EXPECT_EQ(a.OnAnnouncement({10'000'001, 1, kA}, true, 0), AnnouncementVerdict::kFuture);
  EXPECT_EQ(a.OnAnnouncement({9'749'999, 1, kA}, true, 0), AnnouncementVerdict::kStale);
  EXPECT_FALSE(a.has_session());
  EXPECT_EQ(a.OnAnnouncement({9'750'000, 4, kA}, true, 0), AnnouncementVerdict::kAdopted);
  EXPECT_EQ(a.OnAnnouncement({9'800'000, 4, kA}, true, 0), AnnouncementVerdict::kSeqNotIncreasing);
  EXPECT_EQ(a.OnAnnouncement({9'800'000, 5, kA}, true, 0), AnnouncementVerdict::kRenewed);
  EXPECT_EQ(a.announcement_verdicts()[kAnnouncementVerdictNames.Index(AnnouncementVerdict::kStale)],
            1);
  EXPECT_TRUE(IsRejection(AnnouncementVerdict::kSessionBusy));
  EXPECT_FALSE(IsRejection(AnnouncementVerdict::kRenewed));
}

// lcm-logplayer on the same URL: the log's announcements carry the times of
// the run they were recorded in, far from the receiver's samples, so its
// session is never adopted and its commands are someone else's.
TEST(SafeCommandAcceptor, AReplayedLogOfAnOldSessionIsNotAdopted) {
  SafeCommandAcceptor a(kLimits);
  a.OnSamplePublished(1'700'000'100'000'000);  // real time: the epoch's microseconds
  // The log's session, from a run an hour earlier.
  EXPECT_EQ(a.OnAnnouncement({1'700'000'100'000'000 - 3'600'000'000, 900, kB}, true, 0),
            AnnouncementVerdict::kStale);
  EXPECT_FALSE(a.has_session());
  EXPECT_EQ(a.Check(Command(kB, 901, 1'700'000'100'000'000 - 3'600'000'000), true),
            CommandRejection::kNoSession);
  // The live safety announces; the log keeps playing.
  ASSERT_EQ(a.OnAnnouncement({1'700'000'100'000'000, 1, kA}, true, 0),
            AnnouncementVerdict::kAdopted);
  EXPECT_EQ(a.Check(Command(kB, 902, 1'700'000'100'000'000), true),
            CommandRejection::kWrongSession);
  EXPECT_EQ(a.Check(Command(kA, 1, 1'700'000'100'000'000), true), CommandRejection::kNone);
}

// A replay of the current session's own log (its id is right): the seq has
// moved on, and the samples are old.
TEST(SafeCommandAcceptor, AReplayOfTheCurrentSessionIsRefusedBySeqAndAge) {
  SafeCommandAcceptor a = Following();
  ASSERT_EQ(a.Check(Command(kA, 500, 10'000'000), true), CommandRejection::kNone);
  EXPECT_EQ(a.Check(Command(kA, 200, 10'000'000), true), CommandRejection::kSeqNotIncreasing);
  a.OnSamplePublished(20'000'000);
  EXPECT_EQ(a.Check(Command(kA, 501, 10'000'000), true), CommandRejection::kStaleSample);
}

// A second live stack on the bus: the session followed stays, the other's
// announcements are refused as long as the first keeps announcing.
TEST(SafeCommandAcceptor, ASecondLiveSessionDoesNotTakeOver) {
  SafeCommandAcceptor a = Following();
  int64_t t = 10'000'000;
  int64_t wall = 0;
  for (int k = 0; k < 50; ++k) {  // 5 s of both announcing at 10 Hz
    t += 100'000;
    wall += 100'000;
    a.OnSamplePublished(t);
    EXPECT_EQ(a.OnAnnouncement({t, 2 + k, kA}, true, wall), AnnouncementVerdict::kRenewed);
    EXPECT_EQ(a.OnAnnouncement({t, 2 + k, kB}, true, wall), AnnouncementVerdict::kSessionBusy);
  }
  EXPECT_EQ(a.session_id(), kA);
  EXPECT_EQ(a.sessions_adopted(), 1);
}

// A restarted safety process (a new session) is followed once the old one
// has been silent for session_silence of stack time ...
TEST(SafeCommandAcceptor, ANewSessionIsAdoptedAfterTheOldOneFellSilent) {
  SafeCommandAcceptor a = Following();  // renewed at 9.999 s, wall 0
  ASSERT_EQ(a.Check(Command(kA, 900, 10'000'000), true), CommandRejection::kNone);
  a.OnSamplePublished(10'299'000);
  EXPECT_EQ(a.OnAnnouncement({10'299'000, 1, kB}, true, 1000), AnnouncementVerdict::kSessionBusy);
  a.OnSamplePublished(10'299'001);
  ASSERT_EQ(a.OnAnnouncement({10'299'001, 1, kB}, true, 1000), AnnouncementVerdict::kAdopted);
  EXPECT_EQ(a.session_id(), kB);
  EXPECT_EQ(a.sessions_adopted(), 2);
  // Its seq starts afresh; the old session's commands are refused now.
  EXPECT_EQ(a.Check(Command(kB, 1, 10'299'001), true), CommandRejection::kNone);
  EXPECT_EQ(a.Check(Command(kA, 901, 10'299'001), true), CommandRejection::kWrongSession);
}

// ... or of wall time: in lockstep the plant's sample time stops while it
// waits for an answer that the dead session will never send.
TEST(SafeCommandAcceptor, InLockstepWallTimeSilenceLetsANewSessionIn) {
  SafeCommandAcceptor a = Following();
  EXPECT_EQ(a.OnAnnouncement({10'000'000, 1, kB}, true, 1'500'000),
            AnnouncementVerdict::kSessionBusy);
  EXPECT_EQ(a.OnAnnouncement({10'000'000, 1, kB}, true, 1'500'001), AnnouncementVerdict::kAdopted);
}

// A stale announcement of the current session does not keep it alive: an
// estimator stopped for 0.5 s leaves safety announcing an old utime.
TEST(SafeCommandAcceptor, StaleAnnouncementsDoNotRenew) {
  SafeCommandAcceptor a = Following();
  a.OnSamplePublished(10'400'000);
  EXPECT_EQ(a.OnAnnouncement({9'999'000, 2, kA}, true, 400'000), AnnouncementVerdict::kStale);
  EXPECT_EQ(a.OnAnnouncement({10'400'000, 1, kB}, true, 400'000), AnnouncementVerdict::kAdopted);
}

TEST(SafeCommandAcceptor, InvariantsAreChecked) {
  SafeCommandAcceptorLimits bad;
  bad.command_max_age_us = 0;
  EXPECT_THROW(SafeCommandAcceptor{bad}, std::logic_error);
  SafeCommandAcceptor a(kLimits);
  a.OnSamplePublished(2000);
  a.OnSamplePublished(2000);  // lockstep re-sends a sample: same time is fine
  EXPECT_THROW(a.OnSamplePublished(1000), std::logic_error);
}

}  // namespace
}  // namespace stewart
