#include "stewart/guard/safe_command_acceptor.h"

#include "stewart/common/check.h"

namespace stewart {

SafeCommandAcceptor::SafeCommandAcceptor(const SafeCommandAcceptorLimits& limits)
    : limits_(limits) {
  STEWART_CHECK(limits.command_max_age_us > 0 && limits.session_max_age_us > 0 &&
                    limits.session_silence_us > 0 && limits.session_silence_wall_us > 0,
                "SafeCommandAcceptor: every limit must be positive");
}

void SafeCommandAcceptor::OnSamplePublished(int64_t sample_utime) {
  STEWART_CHECK(!have_sample_ || sample_utime >= newest_sample_utime_,
                "SafeCommandAcceptor: sample time went backwards");
  have_sample_ = true;
  newest_sample_utime_ = sample_utime;
}

bool SafeCommandAcceptor::CurrentSessionSilent(int64_t wall_us) const {
  return newest_sample_utime_ - renewed_utime_ > limits_.session_silence_us ||
         wall_us - renewed_wall_us_ > limits_.session_silence_wall_us;
}

AnnouncementVerdict SafeCommandAcceptor::Judge(const SessionAnnouncement& a, bool authentic,
                                               int64_t wall_us) const {
  if (!authentic) return AnnouncementVerdict::kUnauthentic;
  if (a.session_id == 0) return AnnouncementVerdict::kZeroSession;
  if (!have_sample_) return AnnouncementVerdict::kNoSample;
  if (a.utime > newest_sample_utime_) return AnnouncementVerdict::kFuture;
  if (newest_sample_utime_ - a.utime > limits_.session_max_age_us) {
    return AnnouncementVerdict::kStale;
  }
  if (a.session_id == session_id_) {
    return a.seq > announcement_seq_ ? AnnouncementVerdict::kRenewed
                                     : AnnouncementVerdict::kSeqNotIncreasing;
  }
  if (has_session() && !CurrentSessionSilent(wall_us)) return AnnouncementVerdict::kSessionBusy;
  return AnnouncementVerdict::kAdopted;
}

AnnouncementVerdict SafeCommandAcceptor::OnAnnouncement(const SessionAnnouncement& a,
                                                        bool authentic, int64_t wall_us) {
  const AnnouncementVerdict verdict = Judge(a, authentic, wall_us);
  ++announcement_verdicts_[kAnnouncementVerdictNames.Index(verdict)];
  if (IsRejection(verdict)) return verdict;
  if (verdict == AnnouncementVerdict::kAdopted) {
    session_id_ = a.session_id;
    have_command_seq_ = false;  // seq counts within a session
    ++sessions_adopted_;
  }
  announcement_seq_ = a.seq;
  renewed_utime_ = a.utime;
  renewed_wall_us_ = wall_us;
  return verdict;
}

CommandRejection SafeCommandAcceptor::Check(const ForceCommand& c, bool authentic) {
  CommandRejection r = CommandRejection::kNone;
  // Finiteness last: a non-finite force from the current session, fresh and
  // in order, is the filter's failure (hw_bridge zeroes the drive at once),
  // not someone else's message.
  if (!authentic) {
    r = CommandRejection::kUnauthentic;
  } else if (!has_session()) {
    r = CommandRejection::kNoSession;
  } else if (c.session_id != session_id_) {
    r = CommandRejection::kWrongSession;
  } else if (have_command_seq_ && c.seq <= command_seq_) {
    r = CommandRejection::kSeqNotIncreasing;
  } else if (!have_sample_) {
    r = CommandRejection::kNoSample;
  } else if (c.sample_utime > newest_sample_utime_) {
    r = CommandRejection::kFutureSample;
  } else if (newest_sample_utime_ - c.sample_utime > limits_.command_max_age_us) {
    r = CommandRejection::kStaleSample;
  } else if (!c.force_n.allFinite()) {
    r = CommandRejection::kNonFiniteForce;
  }
  if (r != CommandRejection::kNone) {
    ++command_rejections_[kCommandRejectionNames.Index(r)];
    return r;
  }
  have_command_seq_ = true;
  command_seq_ = c.seq;
  ++accepted_;
  return r;
}

}  // namespace stewart
