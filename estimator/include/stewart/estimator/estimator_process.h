#pragma once
// The estimator process's decisions, without LCM: which commands and sensor
// samples reach the EKF, which EKF events are counted as rejections, when an
// estimate is published and with which status, and the perfect-state mode
// (ground truth republished, testing only). The node (estimator/node)
// converts messages and publishes; replay drives the same class.
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

#include "stewart/common/health_counters.h"
#include "stewart/common/input_time_check.h"
#include "stewart/common/resend_answer.h"
#include "stewart/common/signals.h"
#include "stewart/estimator/ekf.h"
#include "stewart/guard/safe_command_acceptor.h"

namespace stewart {

/// The state estimate of an EKF estimate: utime = sample_utime = the sensor
/// sample's utime; status VALID or INITIALIZING, plus DIVERGED.
StateSample StateFromEstimate(const Estimate& estimate, int64_t seq);

class EstimatorProcess {
 public:
  /// `counters` must outlive this object.
  /// `time`: lcm.time_window_s, lcm.max_time_rate. A stream of samples
  /// rejected whole for longer than estimator.max_dt_s (the gap after which
  /// the EKF restarts) is a FAULT.
  /// `trust`: believe a safe command only when the actuators would apply it
  /// (guard/safe_command_acceptor.h: the announced safety session, its MAC,
  /// rising seq, a fresh sample), so a forgery the plant drops cannot move
  /// the estimate either. Absent: every finite command with a plausible time
  /// (the in-process loop, which hands over the safety process's own output).
  /// `guard_force_limit_n`: the actuators' guard.leg_force_limit_n (N). A
  /// command beyond it in magnitude on any leg trips their guard, which turns
  /// the drive off instead of applying it: the process model takes such a
  /// command as drive off and counts it (`command_beyond_guard_force`), so a
  /// command the actuators never apply (a replayed forgery that replaced a
  /// real command lost on the way, without a key) cannot wreck the estimate.
  EstimatorProcess(const PlatformParams& platform, const ActuatorConfig& actuators,
                   const SensorConfig& sensors, const EstimatorConfig& estimator,
                   const Vector6d& home_pose, HealthCounters* counters,
                   const TimePlausibilityParams& time = {},
                   std::optional<SafeCommandAcceptorLimits> trust = std::nullopt,
                   double guard_force_limit_n = std::numeric_limits<double>::infinity());

  /// A safety session announcement (supervisor_state_t); `authentic`: its
  /// MAC verified (true without a key); `wall_us`: the receiver's monotonic
  /// clock. Without `trust`, nothing to decide: kAdopted, ignored.
  AnnouncementVerdict OnAnnouncement(const SessionAnnouncement& announcement, bool authentic,
                                     int64_t wall_us);
  /// A safe command arrived: the process model's input (non-finite ones,
  /// ones with an implausible time and, with `trust`, ones the actuators
  /// would not apply are rejected and counted). Returns true when `out`
  /// holds an estimate to publish: that of a sample that waited for this
  /// command (see OnSensor).
  bool OnCommand(const ForceCommand& command, StateSample* out,
                 std::optional<int64_t> receive_wall_us = std::nullopt, bool authentic = true);
  /// A sensor sample arrived. Returns true when `out` holds an estimate to
  /// publish. The sample last answered, received again (plant_sim's lockstep
  /// resend: an answer was lost downstream), is answered again with the same
  /// estimate without a second EKF update (common/resend_answer.h; counted
  /// `resends_answered`).
  ///
  /// A sample whose source applied the answer to the previous sample
  /// (previous_answer_applied, lockstep) while that answer has not arrived
  /// here waits for it: multicast keeps the order of one sender only, and
  /// the plant's sample can overtake the safety process's command on the
  /// way to this socket (seen in about one tick in five on two busy cores).
  /// Predicting with the command before it would make a lockstep run
  /// depend on the scheduler. The answer's arrival releases the sample
  /// (OnCommand); so do a newer sample and FlushWaiting (counted
  /// `answer_not_heard`: the EKF then predicts with what it has).
  bool OnSensor(const SensorSample& sample, StateSample* out,
                std::optional<int64_t> receive_wall_us = std::nullopt);
  /// A sample waiting for its answer longer than kAnswerWait_s of wall time
  /// (`wall_us`, the receive clock) is updated without it. Returns true when
  /// `out` holds its estimate. The node calls it between reads.
  bool FlushWaiting(int64_t wall_us, StateSample* out);
  /// Whether a sample waits for its answer (the node then polls often).
  bool waiting() const { return waiting_.has_value(); }
  /// Below plant_sim's lockstep resend period (0.2 s), so a command lost to
  /// this process alone costs one late estimate, not a resend.
  static constexpr double kAnswerWait_s = 0.05;
  /// Perfect-state mode: the ground truth, republished as the estimate.
  bool OnTruth(const StateSample& truth, StateSample* out,
               std::optional<int64_t> receive_wall_us = std::nullopt);

  const Ekf& ekf() const { return ekf_; }
  /// The EKF events (EkfEvent bits) of the last sample updated: what a
  /// trajectory shows beside the estimate (which sensors were gated).
  uint32_t last_update_events() const { return last_update_events_; }
  /// Ekf::ShareModelTerms.
  void ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared) {
    ekf_.ShareModelTerms(std::move(shared));
  }
  /// The acceptor of `trust` (nullptr without it).
  const SafeCommandAcceptor* acceptor() const { return acceptor_ ? &*acceptor_ : nullptr; }

 private:
  /// Publishing bookkeeping: non-finite estimates are rejected, never sent.
  bool Emit(const StateSample& state, StateSample* out);
  /// The EKF update of an accepted sample and its estimate.
  bool Update(const SensorSample& sample, StateSample* out, std::optional<int64_t> receive_wall_us);
  /// The waiting sample, updated now (its answer came, or will not).
  bool ReleaseWaiting(StateSample* out);

  struct WaitingSample {
    SensorSample sample;
    std::optional<int64_t> receive_wall_us;
    int64_t answer_utime = 0;  ///< the sample_utime of the answer it waits for
  };

  Ekf ekf_;
  HealthCounters* counters_;
  InputTimeCheck time_check_;
  std::optional<SafeCommandAcceptor> acceptor_;
  double guard_force_limit_n_;
  ResendAnswer resend_;
  StateSample last_answer_;  ///< the estimate answering the sample resend_ holds
  int64_t seq_ = 0;
  std::optional<WaitingSample> waiting_;
  int64_t last_sample_utime_ = -1;    ///< the newest sample updated (or waiting)
  int64_t newest_answer_utime_ = -1;  ///< the newest sample_utime of a plausible command
  uint32_t last_update_events_ = 0;
};

}  // namespace stewart
