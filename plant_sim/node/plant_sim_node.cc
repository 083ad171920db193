#include "plant_sim_node.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "stewart/guard/guard_limits.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/operator_reset.h"
#include "stewart/node/signal_messages.h"
#include "stewart/node/stop_signal.h"
#include "stewart/plant_sim/lockstep_pacing.h"
#include "stewart/plant_sim/real_time_pacing.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

int64_t WallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t MonotonicMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(Clock::now().time_since_epoch())
      .count();
}

int64_t PeriodUs(double rate_hz) {
  const int64_t period_us = std::llround(1e6 / rate_hz);
  if (period_us <= 0) throw std::invalid_argument("sensors.rate_hz is too high (period < 1 us)");
  return period_us;
}

}  // namespace

PlantSimNode::PlantSimNode(const StackConfig& config, const PlantTruth& truth, lcm::LCM* lcm,
                           const PlantSimOptions& options)
    : config_(config),
      options_(options),
      lcm_(lcm),
      receiver_(config.lcm.url),
      plant_(PlantModelOf(truth, config), OdeOptionsFrom(config.plant_sim)),
      sensors_(truth.sensors, truth.actuators, truth.platform.gravity_mps2, truth.sensor_errors),
      disturbance_(truth.disturbance, truth.sensors.seed),
      health_("plant_sim", config.lcm.channels.health, config.lcm.health_rate_hz),
      hold_(SecondsToMicros(config.plant_sim.command_timeout_s)),
      auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      // The stroke the stack believes in (the config's), read by the plant's
      // own pots: a truth with other legs shows up as it would on the device.
      guard_(ActuatorGuardLimitsOf(config.guard, config.platform.leg_min_length_m,
                                   config.platform.leg_max_length_m)),
      operator_check_(SecondsToMicros(config.supervisor.operator_time_window_s)),
      period_us_(PeriodUs(config.sensors.rate_hz)),
      gate_(options.mode == SimMode::kLockstep,
            AcceptorLimitsOf(config.guard, config.plant_sim.command_timeout_s)),
      latency_tracker_(0, period_us_),
      tick_accounting_(0, period_us_) {
  plant_.Reset(0.0, truth.initial_pose, truth.initial_velocity);
  receiver_.Subscribe(config.lcm.channels.command_safe, &PlantSimNode::HandleCommand, this);
  receiver_.Subscribe(config.lcm.channels.supervisor, &PlantSimNode::HandleSupervisor, this);
  receiver_.Subscribe(config.lcm.channels.operator_command, &PlantSimNode::HandleOperator, this);
  spdlog::info(
      "plant_sim: commands accepted from the safety session announced on {}{}",
      config.lcm.channels.supervisor,
      auth_.enabled() ? ", authenticated (lcm.auth_key_file)" : ", no key: not authenticated");
}

ExitCode PlantSimNode::Run() {
  ExitCode status = ExitCode::kOk;
  const Clock::time_point started = Clock::now();
  try {
    health_.SetState(health_t::STATE_OK);
    status = options_.mode == SimMode::kLockstep ? RunLockstep() : RunRealTime();
  } catch (const std::exception& e) {
    spdlog::error("plant_sim: {}", e.what());
    health_.SetState(health_t::STATE_FAULT);
    health_.SetError(e.what());
    status = ExitCode::kIntegrationFailure;
  }
  if (status == ExitCode::kOk) health_.SetState(health_t::STATE_STOPPED);
  UpdateLatencyCounters();
  UpdateTrustCounters();
  health_.MaybePublish(lcm_, true);
  spdlog::info(
      "plant_sim: sample-to-command latency p50 {} us, p99 {} us, max {} us ({} answered "
      "samples)",
      latency_.Percentile(0.50), latency_.Percentile(0.99), latency_.max_us(), latency_.count());
  if (options_.mode == SimMode::kRealTime) {
    spdlog::info(
        "plant_sim: missed ticks {} (stack late {}, plant late {}), overruns {}, tick "
        "lateness p99 {} us, max {} us",
        health_.counter("missed_ticks"), health_.counter("missed_stack_late"),
        health_.counter("missed_plant_late"), health_.counter("overrun_ticks"),
        tick_jitter_.Percentile(0.99), tick_jitter_.max_us());
  }
  const PlantCounters c = plant_.counters();
  const double wall_s = std::chrono::duration<double>(Clock::now() - started).count();
  spdlog::info(
      "plant_sim: stopped at t = {:.3f} s after {} ticks in {:.3f} s of wall time ({:.2f}x "
      "real time); {} end-stop hits, {} rhs evals",
      plant_.time_s(), tick_, wall_s, wall_s > 0.0 ? plant_.time_s() / wall_s : 0.0, c.endstop_hits,
      c.ode.rhs_evals);
  return status;
}

void PlantSimNode::PublishSample() {
  tick_utime_ = utime0_ + tick_ * period_us_;
  const PlantRates& rates = plant_.EvaluateRates();
  const SensorReading r =
      sensors_.Sample(plant_.q(), plant_.qd(), rates.x_dot.segment<6>(6), rates.terms.leg_length_m);
  sensor_t& s = last_sensor_;
  s = sensor_t{};
  s.utime = tick_utime_;
  s.seq = tick_;
  s.sample_utime = tick_utime_;
  ToArray(r.leg_length_m, s.leg_length_m);
  ToArray(r.gyro_radps, s.gyro_radps);
  ToArray(r.accel_mps2, s.accel_mps2);
  s.has_orientation = r.has_orientation;
  ToArray(r.orientation_rpy_rad, s.orientation_rpy_rad);
  s.status = 0;
  if (plant_.InEndStop()) s.status |= sensor_t::STATUS_ENDSTOP;
  if (plant_.actuators_off()) s.status |= sensor_t::STATUS_ACTUATORS_OFF;
  if (answer_applied_) s.status |= sensor_t::STATUS_ANSWER_APPLIED;
  lcm_->publish(config_.lcm.channels.sensors, &s);
  latency_tracker_.OnPublished(tick_, tick_utime_, Clock::now());
  gate_.OnSamplePublished(tick_utime_);
  CheckGuard(r.leg_length_m);

  state_t truth{};
  truth.utime = tick_utime_;
  truth.seq = tick_;
  truth.sample_utime = tick_utime_;
  ToArray(plant_.q(), truth.q);
  ToArray(plant_.qd(), truth.qd);
  truth.status = state_t::STATUS_VALID | state_t::STATUS_GROUND_TRUTH;
  lcm_->publish(config_.lcm.channels.state_truth, &truth);
  health_.CountOut();
  health_.CountOut();
  health_.SetStackTime(tick_utime_, tick_utime_);
}

void PlantSimNode::AdvanceTick() {
  plant_.SetExternalWrench(disturbance_.WrenchAt(plant_.time_s()));
  plant_.Advance(static_cast<double>(period_us_) * 1e-6);
  const PlantCounters c = plant_.counters();
  health_.SetCounter("endstop_hits", c.endstop_hits);
  health_.SetCounter("stiff_fallbacks", c.stiff_fallbacks);
  health_.SetCounter("self_lock_engagements", c.self_lock_engagements);
  health_.SetCounter("ticks", tick_ + 1);
  if (tick_ % 100 == 0) {
    UpdateLatencyCounters();
    UpdateTrustCounters();
    ReportReceiverCounters(receiver_, &health_);
  }
  UpdateHealthState();
  health_.MaybePublish(lcm_);
}

void PlantSimNode::CheckGuard(const Vector6d& leg_length_m) {
  // plant_sim's pots have no fault model: every reading is plausible; a
  // non-finite one still trips.
  if (!guard_.OnReadings(tick_utime_, leg_length_m)) return;
  guard_error_ = "guard tripped: " + guard_.Describe() +
                 "; actuators off (lead screws hold) until an operator RESET with the readings "
                 "back inside";
  spdlog::error("plant_sim: t = {:.3f} s: {}", plant_.time_s(), guard_error_);
  UpdateTrustCounters();
  UpdateHealthState();
}

void PlantSimNode::UpdateHealthState() {
  if (guard_.tripped()) {
    health_.SetState(health_t::STATE_FAULT);
    health_.SetError(guard_error_);
  } else if (fallback_active_) {
    health_.SetState(health_t::STATE_DEGRADED);
  } else {
    health_.SetState(health_t::STATE_OK);
  }
}

void PlantSimNode::UpdateTrustCounters() {
  const SafeCommandAcceptor& a = gate_.acceptor();
  health_.SetCounter("safety_session", a.session_id());
  health_.SetCounter("sessions_adopted", a.sessions_adopted());
  health_.SetCounter("commands_trusted", a.accepted());
  health_.SetCounter("applied_age_max_us", applied_age_max_us_);
  health_.SetCounter("guard_tripped", guard_.tripped() ? 1 : 0);
  health_.SetCounter("guard_trips", guard_.trips());
  health_.SetCounter("guard_resets", guard_.resets_cleared());
  health_.SetCounter("guard_resets_refused", guard_.resets_refused());
  // How close the run came to the guard's limits, to size them: um, um/s, mN.
  health_.SetCounter("guard_min_end_distance_um", std::llround(guard_.min_end_distance_m() * 1e6));
  health_.SetCounter("guard_max_speed_umps", std::llround(guard_.max_speed_mps() * 1e6));
  health_.SetCounter("guard_max_force_mn", std::llround(guard_.max_force_n() * 1e3));
}

void PlantSimNode::HandleCommand(const lcm::ReceiveBuffer*, const std::string&,
                                 const force_command_t* msg) {
  health_.CountIn();
  const ForceCommand command = FromMessage(*msg);
  const CommandGate::Decision d = gate_.Check(command, auth_.Verify(*msg));
  if (d.timed) {
    if (const auto latency_us =
            latency_tracker_.OnCommand(msg->sample_utime, tick_, Clock::now())) {
      latency_.Add(*latency_us);
    }
  }
  if (d.action == CommandGate::Action::kReject) {
    health_.Reject(d.reason, d.detail);
    return;
  }
  // The last line: a force beyond the guard's bound, whoever sent it, turns
  // the drive off. A drive-off command carries no force to judge.
  if ((command.flags & kCommandDriveOff) == 0 && guard_.OnForceCommand(command.force_n)) {
    guard_error_ = "guard tripped: " + guard_.Describe() +
                   "; actuators off (lead screws hold) until an operator RESET";
    spdlog::error("plant_sim: t = {:.3f} s: {} (force_command_t seq {})", plant_.time_s(),
                  guard_error_, msg->seq);
    UpdateTrustCounters();
    UpdateHealthState();
  }
  if (d.action == CommandGate::Action::kApply) {
    hold_.OnCommand(command.force_n, command.sample_utime, (command.flags & kCommandDriveOff) != 0);
  }
}

void PlantSimNode::HandleSupervisor(const lcm::ReceiveBuffer*, const std::string&,
                                    const supervisor_state_t* msg) {
  health_.CountIn();
  const SessionAnnouncement a{msg->utime, msg->seq, msg->session_id};
  const AnnouncementVerdict v = gate_.OnAnnouncement(a, auth_.Verify(*msg), MonotonicMicros());
  if (IsRejection(v)) {
    health_.Reject(ToString(v), "supervisor_state_t session " + std::to_string(msg->session_id) +
                                    ", seq " + std::to_string(msg->seq) + ", utime " +
                                    std::to_string(msg->utime) + " (newest sample " +
                                    std::to_string(tick_utime_) + ")");
    return;
  }
  if (v == AnnouncementVerdict::kAdopted) {
    spdlog::info("plant_sim: following safety session {} (announced at utime {})", msg->session_id,
                 msg->utime);
    UpdateTrustCounters();
  }
}

void PlantSimNode::HandleOperator(const lcm::ReceiveBuffer*, const std::string&,
                                  const operator_command_t* msg) {
  // Only RESET concerns the plant (its guard); the supervisor judges the rest.
  if (!AcceptActuatorReset(*msg, auth_.Verify(*msg), WallMicros(), &operator_check_, &health_)) {
    return;
  }
  const bool was_tripped = guard_.tripped();
  const GuardResetResult r = guard_.Reset();
  if (r == GuardResetResult::kCleared) {
    spdlog::warn("plant_sim: guard cleared by operator {} (was: {})", msg->operator_id,
                 guard_error_);
    guard_error_.clear();
    health_.SetError("");
  } else if (was_tripped) {
    spdlog::warn("plant_sim: operator RESET refused: readings not back inside ({})", guard_error_);
  }
  UpdateTrustCounters();
  UpdateHealthState();
}

void PlantSimNode::UpdateLatencyCounters() {
  health_.SetCounter("answered_samples", latency_.count());
  health_.SetCounter("latency_p50_us", latency_.Percentile(0.50));
  health_.SetCounter("latency_p99_us", latency_.Percentile(0.99));
  health_.SetCounter("latency_max_us", latency_.max_us());
  if (tick_jitter_.count() > 0) {  // real time only: how late each tick started
    health_.SetCounter("tick_late_p99_us", tick_jitter_.Percentile(0.99));
    health_.SetCounter("tick_late_max_us", tick_jitter_.max_us());
  }
}

void PlantSimNode::UpdateTickCounters() {
  const TickCounters& t = tick_accounting_.counters();
  health_.SetCounter("overrun_ticks", t.overrun_ticks);
  health_.SetCounter("missed_ticks", t.missed_ticks);
  health_.SetCounter("missed_plant_late", t.missed_plant_late);
  health_.SetCounter("missed_stack_late", t.missed_stack_late);
}

void PlantSimNode::ApplyRealTimeDecision() {
  const RealTimeCommandHold::Decision d = hold_.Decide(tick_utime_);
  const bool off = d.actuators_off || guard_.tripped();
  plant_.SetActuatorsOff(off);
  if (!off) {
    plant_.SetForceCommand(d.force_cmd_n);
    applied_age_max_us_ = std::max(applied_age_max_us_, d.age_us);
  }
  if (d.timed_out != fallback_active_) {
    fallback_active_ = d.timed_out;
    if (d.timed_out) {
      health_.SetError("no force_command_t on " + config_.lcm.channels.command_safe +
                       " younger than " + std::to_string(config_.plant_sim.command_timeout_s) +
                       " s: actuators off, lead screws hold the legs");
      health_.Count("command_timeouts");
      spdlog::warn("plant_sim: command timeout at t = {:.3f} s: actuators off", plant_.time_s());
    } else {
      health_.SetError("");
      spdlog::info("plant_sim: commands resumed at t = {:.3f} s", plant_.time_s());
    }
  }
  health_.SetCounter("fallback_active", fallback_active_ ? 1 : 0);
}

ExitCode PlantSimNode::RunRealTime() {
  utime0_ = options_.start_utime >= 0 ? options_.start_utime
                                      : std::chrono::duration_cast<std::chrono::microseconds>(
                                            std::chrono::system_clock::now().time_since_epoch())
                                            .count();
  latency_tracker_ = LoopLatencyTracker(utime0_, period_us_);
  tick_accounting_ = TickAccounting(utime0_, period_us_);
  UpdateTickCounters();
  const RealTimePacing pacing(period_us_, Clock::now());
  for (tick_ = 0;; ++tick_) {
    const Clock::time_point deadline = pacing.Deadline(tick_);
    while (!StopRequested()) {
      const int64_t wait_us = RealTimePacing::WaitUs(deadline, Clock::now());
      if (wait_us == 0) break;
      receiver_.HandleTimeoutUs(wait_us);
    }
    while (receiver_.HandleTimeout(0) > 0) {
    }
    if (StopRequested()) break;
    const TickAccounting::Outcome outcome = tick_accounting_.OnTickStart(
        tick_, deadline, Clock::now(), gate_.last_applied_sample_utime(), latency_tracker_);
    UpdateTickCounters();
    tick_jitter_.Add(outcome.late_us);
    if (outcome.log_overrun) {
      spdlog::warn("plant_sim: tick {} started {} us late (overrun {})", tick_, outcome.late_us,
                   tick_accounting_.counters().overrun_ticks);
    }
    PublishSample();
    if (options_.duration_s > 0.0 && plant_.time_s() >= options_.duration_s - 1e-9) break;
    ApplyRealTimeDecision();
    AdvanceTick();
  }
  return ExitCode::kOk;
}

ExitCode PlantSimNode::RunLockstep() {
  utime0_ = std::max<int64_t>(options_.start_utime, 0);
  latency_tracker_ = LoopLatencyTracker(utime0_, period_us_);
  LockstepPacing pacing(config_.plant_sim.lockstep_timeout_s, options_.startup_republish_s);
  for (tick_ = 0;; ++tick_) {
    PublishSample();
    if (options_.duration_s > 0.0 && plant_.time_s() >= options_.duration_s - 1e-9) break;
    pacing.StartWaiting(tick_, Clock::now());
    while (!gate_.answered()) {
      if (StopRequested()) return ExitCode::kOk;
      const LockstepPacing::Step step = pacing.Poll(Clock::now());
      if (step.timed_out) {
        const std::string what = "lockstep: no force_command_t on " +
                                 config_.lcm.channels.command_safe + " with sample_utime " +
                                 std::to_string(tick_utime_) + " (tick " + std::to_string(tick_) +
                                 ") within " +
                                 std::to_string(config_.plant_sim.lockstep_timeout_s) + " s";
        spdlog::error("plant_sim: {}", what);
        health_.SetState(health_t::STATE_FAULT);
        health_.SetError(what);
        return ExitCode::kLockstepTimeout;
      }
      if (step.resend) {
        lcm_->publish(config_.lcm.channels.sensors, &last_sensor_);
        if (tick_ > 0) health_.Count("lockstep_resends");
      }
      receiver_.HandleTimeout(step.wait_ms);
      health_.MaybePublish(lcm_);
    }
    // The answer moves the loop on; a drive-off answer or a tripped guard
    // leaves the actuators off for this period (the lead screws hold).
    const ForceCommand& answer = gate_.answer();
    const bool off = guard_.tripped() || (answer.flags & kCommandDriveOff) != 0;
    plant_.SetActuatorsOff(off);
    if (!off) plant_.SetForceCommand(answer.force_n);
    answer_applied_ = true;  // over the whole next period: the next sample says so
    AdvanceTick();
  }
  return ExitCode::kOk;
}

}  // namespace stewart
