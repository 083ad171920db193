#pragma once
// Which safe commands (CMD_SAFE) may move the platform: the actuators'
// (plant_sim, hw_bridge) half of the trust model (docs/operations.md, "Trust
// model"). LCM multicast lets anyone on the group publish on any channel, so
// the actuators follow one safety session at a time, the one the safety
// process announces on SUPERVISOR (supervisor_state_t), and of its commands
// only those
//   - that are authentic (their MAC verifies; always, without a key),
//   - of the current session,
//   - with seq strictly increasing within the session,
//   - whose sample_utime is not ahead of the receiver's newest published
//     sample and not older than the command age limit against it.
// A session is adopted only from an authentic, fresh announcement: its utime
// (the stack time of the newest state estimate safety saw) within
// session_max_age of the newest sample and not ahead of it. Stack time is the
// receiver's own sample time, so a replayed log, whose times are those of an
// old run, announces nothing fresh. A different session replaces the current
// one only after the current one has gone silent (no fresh announcement for
// session_silence of stack time or session_silence_wall of wall time): two
// live stacks on one bus do not take turns.
//
// No LCM: the node verifies the MAC (node/message_auth.h) and converts the
// messages. No allocation; rejections are counted per reason here and named
// for the health counters (`rejected_<name>`).
#include <array>
#include <cstdint>

#include "stewart/common/enum_table.h"
#include "stewart/common/signals.h"

namespace stewart {

/// Why a safe command was not accepted.
enum class CommandRejection : uint8_t {
  kNone,              ///< accepted
  kUnauthentic,       ///< the MAC does not verify under the configured key
  kNoSession,         ///< no session adopted yet
  kWrongSession,      ///< not the current session (another stack, a replayed log, a forgery)
  kSeqNotIncreasing,  ///< seq not above the last accepted one of the session (a replay)
  kNoSample,          ///< the receiver has published no sample yet to judge its age by
  kFutureSample,      ///< sample_utime ahead of the newest published sample
  kStaleSample,       ///< sample_utime older than the command age limit
  kNonFiniteForce,    ///< NaN or Inf in force_n (of an otherwise trusted command)
};
/// In the order Check tests them.
inline constexpr EnumTable<CommandRejection, 9> kCommandRejectionNames{{{
    {CommandRejection::kNone, "none"},
    {CommandRejection::kUnauthentic, "command_unauthentic"},
    {CommandRejection::kNoSession, "command_no_session"},
    {CommandRejection::kWrongSession, "command_wrong_session"},
    {CommandRejection::kSeqNotIncreasing, "command_seq_not_increasing"},
    {CommandRejection::kNoSample, "command_before_first_sample"},
    {CommandRejection::kFutureSample, "command_future_sample"},
    {CommandRejection::kStaleSample, "command_stale_sample"},
    {CommandRejection::kNonFiniteForce, "non_finite_force"},
}}};
inline const char* ToString(CommandRejection r) { return kCommandRejectionNames.Name(r).data(); }

/// What a session announcement (supervisor_state_t) did.
enum class AnnouncementVerdict : uint8_t {
  kAdopted,           ///< a new session: its commands are accepted from now on
  kRenewed,           ///< the current session, announced fresh again
  kUnauthentic,       ///< MAC does not verify
  kZeroSession,       ///< session_id 0 is never a session
  kNoSample,          ///< no sample published yet to judge its age by
  kStale,             ///< utime older than session_max_age against the newest sample
  kFuture,            ///< utime ahead of the newest sample
  kSeqNotIncreasing,  ///< the current session's, but not newer than its last (a replay)
  kSessionBusy,       ///< another session, while the current one is alive
};
inline constexpr EnumTable<AnnouncementVerdict, 9> kAnnouncementVerdictNames{{{
    {AnnouncementVerdict::kAdopted, "adopted"},
    {AnnouncementVerdict::kRenewed, "renewed"},
    {AnnouncementVerdict::kUnauthentic, "supervisor_unauthentic"},
    {AnnouncementVerdict::kZeroSession, "supervisor_zero_session"},
    {AnnouncementVerdict::kNoSample, "supervisor_before_first_sample"},
    {AnnouncementVerdict::kStale, "supervisor_stale"},
    {AnnouncementVerdict::kFuture, "supervisor_future"},
    {AnnouncementVerdict::kSeqNotIncreasing, "supervisor_seq_not_increasing"},
    {AnnouncementVerdict::kSessionBusy, "supervisor_session_busy"},
}}};
inline const char* ToString(AnnouncementVerdict v) {
  return kAnnouncementVerdictNames.Name(v).data();
}
/// kAdopted and kRenewed are not rejections.
inline bool IsRejection(AnnouncementVerdict v) {
  return v != AnnouncementVerdict::kAdopted && v != AnnouncementVerdict::kRenewed;
}

/// The fields of supervisor_state_t the acceptor needs.
struct SessionAnnouncement {
  int64_t utime = 0;  ///< stack time of the newest state estimate safety saw
  int64_t seq = 0;
  int64_t session_id = 0;
};

struct SafeCommandAcceptorLimits {
  int64_t command_max_age_us = 50'000;          ///< the process's command_timeout_s
  int64_t session_max_age_us = 250'000;         ///< guard.session_max_age_s
  int64_t session_silence_us = 300'000;         ///< guard.session_silence_s
  int64_t session_silence_wall_us = 1'500'000;  ///< guard.session_silence_wall_s
};

class SafeCommandAcceptor {
 public:
  /// Throws std::logic_error on a non-positive limit.
  explicit SafeCommandAcceptor(const SafeCommandAcceptorLimits& limits);

  /// The receiver published its sensor sample `sample_utime`: the time every
  /// age is measured against. Must not go backwards (checked).
  void OnSamplePublished(int64_t sample_utime);

  /// A session announcement; `authentic`: its MAC verified (true without a
  /// key); `wall_us`: the receiver's monotonic clock (session silence).
  AnnouncementVerdict OnAnnouncement(const SessionAnnouncement& a, bool authentic, int64_t wall_us);

  /// A safe command: kNone when it is accepted (and its seq becomes the
  /// session's last), else why not. Rejected commands change nothing.
  CommandRejection Check(const ForceCommand& command, bool authentic);

  bool has_session() const { return session_id_ != 0; }
  int64_t session_id() const { return session_id_; }
  int64_t newest_sample_utime() const { return newest_sample_utime_; }
  int64_t sessions_adopted() const { return sessions_adopted_; }
  int64_t accepted() const { return accepted_; }
  /// Rejected commands per CommandRejection (index kCommandRejectionNames.Index).
  const std::array<int64_t, kCommandRejectionNames.size()>& command_rejections() const {
    return command_rejections_;
  }
  const std::array<int64_t, kAnnouncementVerdictNames.size()>& announcement_verdicts() const {
    return announcement_verdicts_;
  }

 private:
  AnnouncementVerdict Judge(const SessionAnnouncement& a, bool authentic, int64_t wall_us) const;
  bool CurrentSessionSilent(int64_t wall_us) const;

  SafeCommandAcceptorLimits limits_;
  bool have_sample_ = false;
  int64_t newest_sample_utime_ = 0;

  int64_t session_id_ = 0;  // 0: none adopted
  int64_t announcement_seq_ = 0;
  int64_t renewed_utime_ = 0;    // utime of the newest fresh announcement of the session
  int64_t renewed_wall_us_ = 0;  // and when it arrived (receiver's monotonic clock)
  bool have_command_seq_ = false;
  int64_t command_seq_ = 0;  // last accepted seq of the session

  int64_t sessions_adopted_ = 0;
  int64_t accepted_ = 0;
  std::array<int64_t, kCommandRejectionNames.size()> command_rejections_{};
  std::array<int64_t, kAnnouncementVerdictNames.size()> announcement_verdicts_{};
};

}  // namespace stewart
