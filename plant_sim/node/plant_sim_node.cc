#include "plant_sim_node.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "stewart/node/eigen_msg.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/stop_signal.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

OdeOptions OdeOptionsFrom(const PlantSimConfig& c) {
  OdeOptions o;
  o.method = ParseOdeMethod(c.integrator);
  o.rel_tol = c.rel_tol;
  o.abs_tol = c.abs_tol;
  return o;
}

int TimeoutMs(Clock::duration d) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
  return static_cast<int>(std::max<int64_t>(0, std::min<int64_t>(ms, 50)));
}

}  // namespace

PlantSimNode::PlantSimNode(const StackConfig& config, const PlantSimOptions& options)
    : config_(config),
      options_(options),
      lcm_(MakeLcm(config.lcm.url)),
      receiver_(config.lcm.url),
      plant_(PlantModel{config.platform, config.actuators}, OdeOptionsFrom(config.plant_sim)),
      sensors_(config.sensors, config.actuators, config.platform.gravity_mps2),
      health_("plant_sim", config.lcm.channels.health, config.lcm.health_rate_hz),
      hold_(config.plant_sim.command_timeout_s,
            ParseTimeoutFallback(config.plant_sim.timeout_fallback)) {
  period_us_ = std::llround(1e6 / config.sensors.rate_hz);
  if (period_us_ <= 0) throw std::invalid_argument("sensors.rate_hz is too high (period < 1 us)");
  plant_.Reset(0.0, config.plant_sim.initial_pose, config.plant_sim.initial_velocity);
  receiver_.Subscribe(config.lcm.channels.command_safe, &PlantSimNode::HandleCommand, this);
}

int PlantSimNode::Run() {
  int status = 0;
  const Clock::time_point started = Clock::now();
  try {
    health_.SetState(health_t::STATE_OK);
    status = options_.mode == SimMode::kLockstep ? RunLockstep() : RunRealTime();
  } catch (const std::exception& e) {
    spdlog::error("plant_sim: {}", e.what());
    health_.SetState(health_t::STATE_FAULT);
    health_.SetError(e.what());
    status = 4;
  }
  if (status == 0) health_.SetState(health_t::STATE_STOPPED);
  UpdateLatencyCounters();
  health_.MaybePublish(lcm_.get(), true);
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
  lcm_->publish(config_.lcm.channels.sensors, &s);
  const size_t slot = static_cast<size_t>(tick_ % kSentRing);
  sent_sample_utime_[slot] = tick_utime_;
  sent_at_[slot] = std::chrono::steady_clock::now();

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
  plant_.Advance(static_cast<double>(period_us_) * 1e-6);
  const PlantCounters c = plant_.counters();
  health_.SetCounter("endstop_hits", c.endstop_hits);
  health_.SetCounter("ticks", tick_ + 1);
  if (tick_ % 100 == 0) {
    UpdateLatencyCounters();
    ReportReceiverCounters(receiver_, &health_);
  }
  health_.MaybePublish(lcm_.get());
}

void PlantSimNode::HandleCommand(const lcm::ReceiveBuffer*, const std::string&,
                                 const force_command_t* msg) {
  health_.CountIn();
  const Vector6d force_n = FromArray(msg->force_n);
  const std::string problem = ForceCommandProblem(force_n);
  if (!problem.empty()) {
    health_.Reject(problem, "force_command_t seq " + std::to_string(msg->seq));
    return;
  }
  RecordLatency(msg->sample_utime);
  if (options_.mode == SimMode::kLockstep) {
    switch (MatchLockstepCommand(tick_utime_, msg->sample_utime)) {
      case LockstepMatch::kAnswer:
        if (answered_) {
          health_.Reject("duplicate_answer", "sample_utime " + std::to_string(msg->sample_utime));
          return;
        }
        answered_ = true;
        answer_force_n_ = force_n;
        return;
      case LockstepMatch::kStale:
        health_.Reject("stale_sample_utime", std::to_string(msg->sample_utime) + " < awaited " +
                                                 std::to_string(tick_utime_));
        return;
      case LockstepMatch::kFuture:
        health_.Reject("future_sample_utime", std::to_string(msg->sample_utime) + " > awaited " +
                                                  std::to_string(tick_utime_));
        return;
    }
  }
  if (msg->sample_utime > tick_utime_) {
    health_.Reject("future_sample_utime", std::to_string(msg->sample_utime));
    return;
  }
  if (msg->sample_utime < last_applied_sample_utime_) {
    health_.Reject("out_of_order", std::to_string(msg->sample_utime));
    return;
  }
  last_applied_sample_utime_ = msg->sample_utime;
  hold_.OnCommand(force_n, plant_.time_s());
}

void PlantSimNode::RecordLatency(int64_t sample_utime) {
  if (sample_utime <= newest_timed_sample_utime_ || sample_utime < utime0_) return;
  const int64_t tick = (sample_utime - utime0_) / period_us_;
  const size_t slot = static_cast<size_t>(tick % kSentRing);
  if (tick > tick_ || sent_sample_utime_[slot] != sample_utime) return;  // unknown or too old
  newest_timed_sample_utime_ = sample_utime;
  latency_.Add(std::chrono::duration_cast<std::chrono::microseconds>(
                   std::chrono::steady_clock::now() - sent_at_[slot])
                   .count());
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

void PlantSimNode::ApplyRealTimeDecision() {
  const RealTimeCommandHold::Decision d = hold_.Decide(plant_.time_s());
  plant_.SetActuatorsOff(d.actuators_off);
  if (!d.actuators_off) plant_.SetForceCommand(d.force_cmd_n);
  if (d.timed_out != fallback_active_) {
    fallback_active_ = d.timed_out;
    if (d.timed_out) {
      const std::string what =
          d.actuators_off ? "actuators off, lead screws hold the legs" : "holding the last command";
      health_.SetError("no force_command_t on " + config_.lcm.channels.command_safe + " for " +
                       std::to_string(config_.plant_sim.command_timeout_s) + " s: " + what);
      health_.SetState(health_t::STATE_DEGRADED);
      health_.Count("command_timeouts");
      spdlog::warn("plant_sim: command timeout at t = {:.3f} s: {}", plant_.time_s(), what);
    } else {
      health_.SetError("");
      health_.SetState(health_t::STATE_OK);
      spdlog::info("plant_sim: commands resumed at t = {:.3f} s", plant_.time_s());
    }
  }
  health_.SetCounter("fallback_active", fallback_active_ ? 1 : 0);
}

int PlantSimNode::RunRealTime() {
  utime0_ = options_.start_utime >= 0 ? options_.start_utime
                                      : std::chrono::duration_cast<std::chrono::microseconds>(
                                            std::chrono::system_clock::now().time_since_epoch())
                                            .count();
  const auto period = std::chrono::microseconds(period_us_);
  health_.SetCounter("overrun_ticks", 0);
  health_.SetCounter("missed_ticks", 0);
  health_.SetCounter("missed_plant_late", 0);
  health_.SetCounter("missed_stack_late", 0);
  const Clock::time_point start = Clock::now();
  for (tick_ = 0;; ++tick_) {
    const Clock::time_point deadline = start + tick_ * period;
    // Commands are taken in while waiting for the tick; the one newest at
    // the tick acts over the whole following interval (zero-order hold).
    // Waiting on the socket until the deadline (not sleeping) takes each
    // command in as it arrives, so its latency is measured when it lands.
    while (!StopRequested()) {
      const Clock::duration left = deadline - Clock::now();
      if (left <= Clock::duration::zero()) break;
      receiver_.HandleTimeoutUs(std::min<int64_t>(
          std::chrono::duration_cast<std::chrono::microseconds>(left).count() + 1, 50000));
    }
    while (receiver_.HandleTimeout(0) > 0) {
    }
    if (StopRequested()) break;
    // Real-time bookkeeping (docs/simulation.md, "Real-time figures"):
    // an overrun is a tick started more than one period after its deadline
    // (the simulator itself fell behind); a missed tick is one whose previous
    // sample got no command before this tick, so the stale one stays applied.
    const Clock::duration late = Clock::now() - deadline;
    tick_jitter_.Add(std::chrono::duration_cast<std::chrono::microseconds>(late).count());
    if (late > period) {
      health_.Count("overrun_ticks");
      const int64_t overruns = health_.counter("overrun_ticks");
      if (overruns <= 20 || overruns % 100 == 0) {  // the exceptional path only
        spdlog::warn("plant_sim: tick {} started {} us late (overrun {})", tick_,
                     std::chrono::duration_cast<std::chrono::microseconds>(late).count(), overruns);
      }
    }
    if (tick_ > 0) {
      const int64_t previous_sample_utime = utime0_ + (tick_ - 1) * period_us_;
      if (last_applied_sample_utime_ < previous_sample_utime) {
        health_.Count("missed_ticks");
        // Whose: the stack had less than half a period when the plant itself
        // published the previous sample late (it catches up on the wall clock).
        const Clock::duration window =
            Clock::now() - sent_at_[static_cast<size_t>((tick_ - 1) % kSentRing)];
        health_.Count(window < period / 2 ? "missed_plant_late" : "missed_stack_late");
      }
    }
    PublishSample();
    if (options_.duration_s > 0.0 && plant_.time_s() >= options_.duration_s - 1e-9) break;
    ApplyRealTimeDecision();
    AdvanceTick();
  }
  return 0;
}

namespace {
constexpr std::chrono::milliseconds kStallResend(200);
}  // namespace

int PlantSimNode::RunLockstep() {
  utime0_ = std::max<int64_t>(options_.start_utime, 0);
  const auto timeout = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(config_.plant_sim.lockstep_timeout_s));
  const auto republish = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.startup_republish_s));
  for (tick_ = 0;; ++tick_) {
    answered_ = false;
    PublishSample();
    if (options_.duration_s > 0.0 && plant_.time_s() >= options_.duration_s - 1e-9) break;
    const Clock::time_point waiting_since = Clock::now();
    Clock::time_point last_sent = waiting_since;
    while (!answered_) {
      if (StopRequested()) return 0;
      const Clock::time_point now = Clock::now();
      if (now - waiting_since >= timeout) {
        const std::string what = "lockstep: no force_command_t on " +
                                 config_.lcm.channels.command_safe + " with sample_utime " +
                                 std::to_string(tick_utime_) + " (tick " + std::to_string(tick_) +
                                 ") within " +
                                 std::to_string(config_.plant_sim.lockstep_timeout_s) + " s";
        spdlog::error("plant_sim: {}", what);
        health_.SetState(health_t::STATE_FAULT);
        health_.SetError(what);
        return 3;
      }
      // Resend the awaited sample: at start-up until the stack has
      // subscribed, later when the loop stalls. On a saturated machine a
      // multicast datagram was seen to wait in the kernel for seconds (or is
      // lost), and lockstep has nothing else to move it along; a receiver
      // that already has the sample rejects the copy by its utime.
      const Clock::duration resend_every = tick_ == 0 ? republish : kStallResend;
      const bool resend_enabled = tick_ > 0 || options_.startup_republish_s > 0.0;
      if (resend_enabled && now - last_sent >= resend_every) {
        // The stored message, byte for byte: a new draw would change the noise sequence.
        lcm_->publish(config_.lcm.channels.sensors, &last_sensor_);
        if (tick_ > 0) health_.Count("lockstep_resends");
        last_sent = now;
      }
      const Clock::duration remaining = timeout - (now - waiting_since);
      receiver_.HandleTimeout(TimeoutMs(std::min<Clock::duration>(remaining, resend_every)));
      health_.MaybePublish(lcm_.get());
    }
    plant_.SetForceCommand(answer_force_n_);
    AdvanceTick();
  }
  return 0;
}

}  // namespace stewart
