#include "stewart/identify/stroke_end_procedure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "sample_checks.h"
#include "stewart/hw_bridge/bringup.h"
#include "stewart/identify/inertial_fit.h"
#include "stewart/model/dc_motor.h"

namespace stewart::identify {
namespace {

// A leg pushed into its stop lags its reference; one that lags less is not
// yet held by the stop (still catching up).
constexpr double kPushedLagM = 1e-3;
// The return to the rest lengths ends within this of them.
constexpr double kReturnToleranceM = 1e-3;

std::string Mm(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f mm", 1e3 * metres);
  return text;
}

class EndRunner {
 public:
  EndRunner(ActuatorDevice* device, const StrokeEndOptions& options, const ProgressFn& progress)
      : device_(device),
        o_(options),
        progress_(progress),
        guard_(StrokeEndGuard(options)),
        back_emf_nspm_(DcMotorBackEmfDampingNspm(options.motor)) {}

  void SendZero() {
    if (have_sample_) device_->SetDuty(last_utime_, Vector6d::Zero());
  }
  Vector6d Rest();
  /// To the ends on side sign (-1 retracted, +1 extended) from the rest
  /// lengths `from`; returns the mean and std of the readings there.
  void ToEnd(int sign, const Vector6d& from, Vector6d* mean_m, Vector6d* std_m);
  /// Back to the lengths `to`.
  void Return(const Vector6d& to);
  long samples() const { return samples_; }
  int64_t first_utime() const { return first_utime_; }
  int64_t last_utime() const { return last_utime_; }

 private:
  const ActuatorSample& Next();
  void Send(const Vector6d& duty);
  [[noreturn]] void Fail(const std::string& reason) {
    SendZero();
    throw IdentificationError(reason);
  }
  void Report(const std::string& line) const {
    if (progress_) progress_(line);
  }
  double FeedForwardDuty(double speed_mps) const {
    return DcMotorDutyForDriveForce(o_.motor, back_emf_nspm_ * speed_mps);
  }

  ActuatorDevice* device_;
  const StrokeEndOptions& o_;
  const ProgressFn& progress_;
  hw::LegGuard guard_;
  double back_emf_nspm_;
  ActuatorSample sample_;
  bool have_sample_ = false;
  int64_t first_utime_ = 0;
  int64_t last_utime_ = 0;
  long samples_ = 0;
};

const ActuatorSample& EndRunner::Next() {
  const ActuatorSample s = device_->NextSample();
  const std::string at = detail::AtUtime(s.utime);
  if (const auto why = detail::UnusableSample(
          s, have_sample_, last_utime_,
          ": a reading outside the calibrated span by more than the fault margin; calibrate that "
          "leg by hand, docs/hardware.md step 2")) {
    Fail(*why);
  }
  if (!have_sample_) first_utime_ = s.utime;
  have_sample_ = true;
  last_utime_ = s.utime;
  ++samples_;
  const uint8_t tripped = guard_.Update(s.utime, s.leg_length_m);
  for (int i = 0; i < kNumLegs; ++i) {
    if ((tripped >> i) & 1U) {
      SendZero();
      const hw::GuardReason reason = guard_.reason(i);
      const bool end =
          reason == hw::GuardReason::kRetractedEnd || reason == hw::GuardReason::kExtendedEnd;
      throw GuardTrip(i, reason, guard_.length_m(i), guard_.speed_mps(i), s.utime,
                      "guard: leg " + std::to_string(i) + " " + hw::ToString(reason) + " at " +
                          std::to_string(s.leg_length_m(i)) + " m" + at +
                          (end ? ", more than " + Mm(o_.search_m) +
                                     " beyond its nominal stroke end without stopping: its pot "
                                     "calibration is further off than the search allows "
                                     "(calibrate it by hand, docs/hardware.md step 2), or the "
                                     "actuator has no end stop there"
                               : std::string()) +
                          ": zero duty sent to every leg");
    }
  }
  if (const int leg = detail::DeviceGuardLeg(s); leg >= 0) {
    SendZero();
    throw GuardTrip(leg, hw::GuardReason::kNone, s.leg_length_m(leg), guard_.speed_mps(leg),
                    s.utime,
                    "the device's guard (hw_bridge --bringup) holds leg " + std::to_string(leg) +
                        " at zero duty" + at +
                        ": a reading beyond the search window (hw_bridge --bringup-end-search "
                        "must be given the run's search distance); zero duty sent to every leg");
  }
  sample_ = s;
  return sample_;
}

void EndRunner::Send(const Vector6d& duty) {
  const Vector6d wanted = duty.cwiseMax(-o_.max_duty).cwiseMin(o_.max_duty);
  const Vector6d allowed = guard_.Apply(wanted);
  if (guard_.limited_mask() != 0) {
    const int leg = __builtin_ctz(guard_.limited_mask());
    Fail("leg " + std::to_string(leg) + " reads " + std::to_string(sample_.leg_length_m(leg)) +
         " m, more than " + Mm(o_.search_m) +
         " beyond its nominal stroke end, and has not stopped: its pot calibration is further off "
         "than the search allows (calibrate it by hand, docs/hardware.md step 2), or the actuator "
         "has no end stop there; zero duty sent");
  }
  device_->SetDuty(last_utime_, allowed);
}

Vector6d EndRunner::Rest() {
  std::vector<Vector6d> readings;
  int64_t start = -1;
  for (;;) {
    const ActuatorSample& s = Next();
    if (start < 0) start = s.utime;
    Send(Vector6d::Zero());
    const double elapsed_s = 1e-6 * static_cast<double>(s.utime - start);
    // The second half: the screws have taken hold.
    if (elapsed_s >= 0.5 * o_.rest_s) readings.push_back(s.leg_length_m);
    if (elapsed_s >= o_.rest_s) break;
  }
  Vector6d mean = Vector6d::Zero();
  for (const Vector6d& r : readings) mean += r;
  return mean / static_cast<double>(readings.size());
}

void EndRunner::ToEnd(int sign, const Vector6d& from, Vector6d* mean_m, Vector6d* std_m) {
  const double s = sign;
  const double end = sign < 0 ? o_.min_length_m : o_.max_length_m;
  const char* side = sign < 0 ? "retracted" : "extended";
  // The path stops where the farthest leg's reference is search_m beyond
  // its end: a leg that has not met a stop by then has none there.
  const double path_end_m = (s * (Vector6d::Constant(end) - from)).maxCoeff() + o_.search_m;
  double path_m = 0.0;
  std::array<int64_t, kNumLegs> anchor_utime{};
  anchor_utime.fill(-1);
  Vector6d anchor_m = Vector6d::Zero();
  std::vector<Vector6d> held;
  int64_t previous = -1, start = -1, hold_start = -1;
  for (;;) {
    const ActuatorSample& smp = Next();
    if (start < 0) start = smp.utime;
    const double dt_s = previous < 0 ? 0.0 : 1e-6 * static_cast<double>(smp.utime - previous);
    previous = smp.utime;
    const Vector6d& length = smp.leg_length_m;
    const Vector6d to_end = s * (Vector6d::Constant(end) - length);
    const bool slow = (to_end.array() < o_.slow_zone_m).any();
    const double speed = slow ? o_.approach_speed_mps : o_.travel_speed_mps;
    path_m = std::min(path_m + speed * dt_s, path_end_m);
    const Vector6d reference = from + Vector6d::Constant(s * path_m);
    const Vector6d lag = s * (reference - length);

    // A leg far from its end that falls behind the others is blocked or not
    // driven; the platform tilts while it does.
    double least_lag = lag.minCoeff();
    for (int i = 0; i < kNumLegs; ++i) {
      if (to_end(i) >= o_.stop_window_m && lag(i) - least_lag > o_.max_lag_m) {
        Fail("leg " + std::to_string(i) + " lags the others by " + Mm(lag(i) - least_lag) +
             " on the way to its " + side + " end, " + Mm(to_end(i)) +
             " before it: blocked, unpowered or a wrong drive sign; zero duty sent");
      }
    }
    // Stopped: the reading stays within stall_band_m of where it last moved
    // to (a speed estimate from 25 ms of pot readings is too noisy for it:
    // one ADC count in 25 ms is 2 mm/s) while the reference pulls it on.
    bool all_at_end = true;
    for (int i = 0; i < kNumLegs; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (anchor_utime[k] < 0 || std::abs(length(i) - anchor_m(i)) > o_.stall_band_m ||
          lag(i) <= kPushedLagM) {
        anchor_m(i) = length(i);
        anchor_utime[k] = smp.utime;
      }
      const bool stalled = 1e-6 * static_cast<double>(smp.utime - anchor_utime[k]) >= o_.stall_s;
      if (stalled && to_end(i) > o_.stop_window_m) {
        Fail("leg " + std::to_string(i) + " stopped " + Mm(to_end(i)) + " before its nominal " +
             side + " end (" + Mm(o_.stop_window_m) +
             " allowed): blocked, or its pot calibration is that far off (calibrate it by hand, "
             "docs/hardware.md step 2); zero duty sent");
      }
      all_at_end = all_at_end && stalled;
    }

    Vector6d duty;
    for (int i = 0; i < kNumLegs; ++i) {
      const double cap = hold_start >= 0              ? o_.hold_duty
                         : to_end(i) < o_.slow_zone_m ? o_.push_duty
                                                      : o_.max_duty;
      duty(i) = std::clamp(
          s * FeedForwardDuty(speed) + o_.gain_duty_per_m * (reference(i) - length(i)), -cap, cap);
    }
    Send(duty);

    if (all_at_end && hold_start < 0) hold_start = smp.utime;
    if (hold_start >= 0) {
      // The first half lets the stops relax to the lighter push.
      const double held_s = 1e-6 * static_cast<double>(smp.utime - hold_start);
      if (held_s >= 0.5 * o_.hold_s) held.push_back(length);
      if (held_s >= o_.hold_s) break;
    }
    if (1e-6 * static_cast<double>(smp.utime - start) > o_.move_timeout_s) {
      Fail(std::string("the legs did not all reach their ") + side + " ends within " +
           std::to_string(o_.move_timeout_s) + " s (path " + Mm(path_m) +
           "): a leg does not move as commanded; zero duty sent");
    }
  }
  Vector6d mean = Vector6d::Zero();
  for (const Vector6d& r : held) mean += r;
  mean /= static_cast<double>(held.size());
  Vector6d var = Vector6d::Zero();
  for (const Vector6d& r : held) var += (r - mean).cwiseAbs2();
  *mean_m = mean;
  *std_m = (var / static_cast<double>(std::max<std::size_t>(held.size() - 1, 1))).cwiseSqrt();
  std::string offsets;
  for (int i = 0; i < kNumLegs; ++i) {
    offsets += (i > 0 ? ", " : "") + Mm(mean(i) - end);
  }
  Report(std::string(side) + " ends reached; readings minus the nominal end: [" + offsets + "]");
}

void EndRunner::Return(const Vector6d& to) {
  const Vector6d from = sample_.leg_length_m;
  const Vector6d distance = to - from;
  double path_m = 0.0;
  const double path_end_m = distance.cwiseAbs().maxCoeff();
  int64_t previous = -1, start = -1;
  for (;;) {
    const ActuatorSample& smp = Next();
    if (start < 0) start = smp.utime;
    const double dt_s = previous < 0 ? 0.0 : 1e-6 * static_cast<double>(smp.utime - previous);
    previous = smp.utime;
    path_m = std::min(path_m + o_.travel_speed_mps * dt_s, path_end_m);
    Vector6d duty;
    for (int i = 0; i < kNumLegs; ++i) {
      const double travelled = std::min(path_m, std::abs(distance(i)));
      const double sign = distance(i) < 0.0 ? -1.0 : 1.0;
      const double reference = from(i) + sign * travelled;
      const double speed = travelled < std::abs(distance(i)) ? o_.travel_speed_mps : 0.0;
      duty(i) = std::clamp(
          sign * FeedForwardDuty(speed) + o_.gain_duty_per_m * (reference - smp.leg_length_m(i)),
          -o_.max_duty, o_.max_duty);
    }
    const bool arrived = path_m >= path_end_m &&
                         ((smp.leg_length_m - to).cwiseAbs().array() < kReturnToleranceM).all();
    Send(arrived ? Vector6d::Zero() : duty);
    if (arrived) return;
    if (1e-6 * static_cast<double>(smp.utime - start) > o_.move_timeout_s) {
      Fail("the legs did not return to their rest lengths within " +
           std::to_string(o_.move_timeout_s) + " s; zero duty sent");
    }
  }
}

}  // namespace

hw::LegGuardLimits StrokeEndGuard(const StrokeEndOptions& o) {
  return hw::StrokeEndSearchGuard(o.min_length_m, o.max_length_m, o.search_m, o.speed_cap_mps);
}

void ValidateStrokeEndOptions(const StrokeEndOptions& o) {
  const auto fail = [](const std::string& what) { throw IdentificationError(what); };
  if (!(o.max_length_m > o.min_length_m && o.min_length_m > 0.0)) {
    fail("stroke ends: need 0 < min_length_m < max_length_m");
  }
  const double positive[] = {
      o.search_m,     o.stop_window_m, o.slow_zone_m, o.travel_speed_mps, o.approach_speed_mps,
      o.max_duty,     o.push_duty,     o.hold_duty,   o.gain_duty_per_m,  o.max_lag_m,
      o.stall_band_m, o.stall_s,       o.hold_s,      o.rest_s,           o.move_timeout_s,
      o.speed_cap_mps};
  for (const double v : positive) {
    if (!(v > 0.0 && std::isfinite(v)))
      fail("stroke-end run: times, distances, speeds and duties must be > 0");
  }
  if (!(o.search_m > 2.0 * StrokeEndGuard(o).margin_m)) {
    fail("stroke-end run: the search distance must exceed 1 mm");
  }
  if (o.max_duty > 1.0 || o.push_duty > o.max_duty || o.hold_duty > o.push_duty) {
    fail("stroke-end run: need hold duty <= push duty <= max duty <= 1");
  }
  if (!(o.approach_speed_mps <= o.travel_speed_mps && o.travel_speed_mps < o.speed_cap_mps)) {
    fail("stroke-end run: need approach speed <= travel speed < the guard's speed cap");
  }
  if (!(o.motor.stall_force_n > 0.0 && o.motor.no_load_speed_mps > 0.0)) {
    fail("stroke-end run: the legs are not DC motors (actuators.motor)");
  }
}

StrokeEndRecord RunStrokeEndProcedure(ActuatorDevice* device, const StrokeEndOptions& options,
                                      const ProgressFn& progress) {
  ValidateStrokeEndOptions(options);
  EndRunner runner(device, options, progress);
  StrokeEndRecord record;
  try {
    record.home_length_m = runner.Rest();
    runner.ToEnd(-1, record.home_length_m, &record.retracted_reading_m, &record.retracted_std_m);
    runner.Return(record.home_length_m);
    const Vector6d between = runner.Rest();
    runner.ToEnd(+1, between, &record.extended_reading_m, &record.extended_std_m);
    runner.Return(record.home_length_m);
    runner.Rest();
  } catch (...) {
    runner.SendZero();
    throw;
  }
  runner.SendZero();
  record.samples = runner.samples();
  record.duration_s = 1e-6 * static_cast<double>(runner.last_utime() - runner.first_utime());
  return record;
}

}  // namespace stewart::identify
