#include "stewart/identify/actuator_procedure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "sample_checks.h"
#include "stewart/identify/ramp_start.h"

namespace stewart::identify {
namespace {

std::string Fmt(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

class Runner {
 public:
  Runner(ActuatorDevice* device, const ActuatorProcedureOptions& options,
         const ProgressFn& progress)
      : device_(device), o_(options), progress_(progress), guard_(options.guard) {}

  LegTestRecord RunLeg(int leg);
  void SendZero() {
    if (have_sample_) device_->SetDuty(last_utime_, Vector6d::Zero());
  }

 private:
  using DutyFn = std::function<double(double elapsed_s)>;
  using DoneFn = std::function<bool(double elapsed_s, double moved_m, double length_m)>;

  const ActuatorSample& Next();
  void Send(int64_t utime, double duty);
  [[noreturn]] void Fail(const std::string& reason);
  [[noreturn]] void Trip(int leg, hw::GuardReason reason);
  ProcedureStep RunStep(StepKind kind, int sign, double timeout_s, const DutyFn& duty,
                        const DoneFn& done);
  void Rest();
  void Report(const std::string& line) const {
    if (progress_) progress_(line);
  }
  std::string LegName() const { return "leg " + std::to_string(leg_); }
  // Half periods vary between 0.75 and 1.25 times half_period_s (a
  // golden-ratio sequence, another stretch of it in every excursion): the
  // level changes fall at other leg lengths each time, so a reading error
  // that depends on the length (ADC steps, the pot's track) does not meet
  // them the same way in every excursion and averages out over them. With
  // one fixed period it did not: the emulator's two ADCs biased the rotor
  // mass by +5 %, more with more repeats.
  double SquareWave(const DutyLevels& levels, double elapsed_s, int excursion) const {
    constexpr double kGolden = 0.6180339887498949;
    double start_s = 0.0;
    for (long n = 0;; ++n) {
      const double phase = static_cast<double>(n + 7L * excursion) * kGolden;
      const double half_s = o_.half_period_s * (0.75 + 0.5 * (phase - std::floor(phase)));
      if (elapsed_s < start_s + half_s) return n % 2 == 0 ? levels.hi : levels.lo;
      start_s += half_s;
    }
  }

  ActuatorDevice* device_;
  const ActuatorProcedureOptions& o_;
  const ProgressFn& progress_;
  hw::LegGuard guard_;
  LegTestRecord* record_ = nullptr;
  int leg_ = 0;
  bool have_sample_ = false;
  int64_t last_utime_ = 0;
  double reference_length_m_ = 0.0;  // the leg's length at the end of the last rest
};

const ActuatorSample& Runner::Next() {
  const ActuatorSample s = device_->NextSample();
  if (const auto why = detail::UnusableSample(s, have_sample_, last_utime_, "")) {
    Fail(*why);
  }
  have_sample_ = true;
  last_utime_ = s.utime;
  record_->samples.push_back(s);
  const uint8_t tripped = guard_.Update(s.utime, s.leg_length_m);
  for (int i = 0; i < kNumLegs; ++i) {
    if ((tripped >> i) & 1U) Trip(i, guard_.reason(i));
  }
  if (const int leg = detail::DeviceGuardLeg(s); leg >= 0) {
    SendZero();
    throw GuardTrip(
        leg, hw::GuardReason::kNone, s.leg_length_m(leg), guard_.speed_mps(leg), s.utime,
        "the device's guard (hw_bridge --bringup) holds leg " + std::to_string(leg) +
            " at zero duty" + detail::AtUtime(s.utime) + ": zero duty sent to every leg");
  }
  return record_->samples.back();
}

void Runner::Fail(const std::string& reason) {
  SendZero();
  throw IdentificationError(reason);
}

void Runner::Trip(int leg, hw::GuardReason reason) {
  SendZero();
  const double length = guard_.length_m(leg);
  const double speed = guard_.speed_mps(leg);
  throw GuardTrip(leg, reason, length, speed, last_utime_,
                  "guard: leg " + std::to_string(leg) + " " + hw::ToString(reason) + " at length " +
                      Fmt("%.4f", length) + " m (stroke " + Fmt("%.4f", o_.guard.min_length_m) +
                      " - " + Fmt("%.4f", o_.guard.max_length_m) + " m, margin " +
                      Fmt("%.4f", o_.guard.margin_m) + " m), speed " + Fmt("%.4f", speed) +
                      " m/s (cap " + Fmt("%.4f", o_.guard.speed_cap_mps) + "), utime " +
                      std::to_string(last_utime_) + ": zero duty sent to every leg");
}

void Runner::Send(int64_t utime, double duty) {
  Vector6d wanted = Vector6d::Zero();
  wanted(leg_) = std::clamp(duty, -o_.max_duty, o_.max_duty);
  const Vector6d allowed = guard_.Apply(wanted);
  if ((guard_.limited_mask() >> leg_) & 1U) {
    Trip(leg_, guard_.length_m(leg_) < 0.5 * (o_.guard.min_length_m + o_.guard.max_length_m)
                   ? hw::GuardReason::kRetractedEnd
                   : hw::GuardReason::kExtendedEnd);
  }
  device_->SetDuty(utime, allowed);
}

ProcedureStep Runner::RunStep(StepKind kind, int sign, double timeout_s, const DutyFn& duty,
                              const DoneFn& done) {
  ProcedureStep step;
  step.kind = kind;
  step.sign = sign;
  step.first_sample = record_->samples.size();
  const double start_length = reference_length_m_;
  int64_t start_utime = -1;
  for (;;) {
    const ActuatorSample& s = Next();
    if (start_utime < 0) start_utime = s.utime;
    const double elapsed_s = static_cast<double>(s.utime - start_utime) * 1e-6;
    const double length = s.leg_length_m(leg_);
    const bool finished = done(elapsed_s, length - start_length, length);
    Send(s.utime, finished ? 0.0 : duty(elapsed_s));
    if (finished) break;
    if (elapsed_s > timeout_s) {
      Fail(LegName() + ": the " + ToString(kind) + " did not finish within " +
           Fmt("%.1f", timeout_s) + " s (moved " + Fmt("%.2f", 1e3 * (length - start_length)) +
           " mm): the leg does not move as commanded (motor supply, wiring, a blocked leg)");
    }
  }
  step.end_sample = record_->samples.size();
  step.moved_m = record_->samples.back().leg_length_m(leg_) - start_length;
  record_->steps.push_back(step);
  return step;
}

void Runner::Rest() {
  const ProcedureStep step = RunStep(
      StepKind::kRest, 0, o_.rest_s + 1.0, [](double) { return 0.0; },
      [this](double elapsed_s, double, double) { return elapsed_s >= o_.rest_s; });
  // The leg's length now: the mean over the rest's second half (at rest,
  // held by its screw; the mean beats the pot's noise).
  const std::size_t first = step.first_sample + (step.end_sample - step.first_sample) / 2;
  double sum = 0.0;
  for (std::size_t k = first; k < step.end_sample; ++k) {
    sum += record_->samples[k].leg_length_m(leg_);
  }
  reference_length_m_ = sum / static_cast<double>(step.end_sample - first);
}

LegTestRecord Runner::RunLeg(int leg) {
  LegTestRecord record;
  record.leg = leg;
  // A leg's test takes ~17 s per repeat at 1 kHz: room for twice that, so
  // the per-sample loop does not reallocate.
  record.samples.reserve(static_cast<std::size_t>(20000 + 20000 * o_.repeats));
  record.steps.reserve(static_cast<std::size_t>(16 + 4 * o_.levels.size() * o_.repeats));
  record_ = &record;
  leg_ = leg;
  Rest();
  record.home_length_m = reference_length_m_;
  const double home = record.home_length_m;
  const hw::LegGuardLimits& g = o_.guard;
  const double room_m =
      std::min(home - (g.min_length_m + g.margin_m), (g.max_length_m - g.margin_m) - home);
  if (room_m < o_.excursion_m + 1e-3) {
    Report(LegName() + ": only " + Fmt("%.1f", 1e3 * room_m) + " mm from the guard's end zone (" +
           Fmt("%.1f", 1e3 * o_.excursion_m) + " mm excursions): the guard may stop the run");
  }

  // Direction: the first motion, small. Either direction counts as motion.
  const ProcedureStep check = RunStep(
      StepKind::kDirectionCheck, 1, o_.move_timeout_s, [this](double) { return o_.check_duty; },
      [this](double, double moved, double) { return std::abs(moved) >= o_.check_distance_m; });
  if (check.moved_m < 0.0) {
    Fail(LegName() + " retracts under positive duty (" + Fmt("%.2f", 1e3 * check.moved_m) +
         " mm at duty " + Fmt("%.2f", o_.check_duty) +
         "): its motor is wired reversed; set hw_bridge.drive_sign[" + std::to_string(leg) +
         "] = -1");
  }
  Rest();
  RunStep(
      StepKind::kReturn, -1, o_.move_timeout_s, [this](double) { return -o_.check_duty; },
      [home](double, double, double length) { return length <= home; });
  Rest();

  // Start ramps, out and back.
  double start_duty[2] = {0.0, 0.0};
  for (const int sign : {1, -1}) {
    RunStep(
        StepKind::kRamp, sign, o_.ramp_max_duty / o_.ramp_rate_per_s + o_.move_timeout_s,
        [this, sign](double elapsed_s) {
          return sign * std::min(o_.ramp_max_duty, o_.ramp_rate_per_s * elapsed_s);
        },
        [this, sign](double, double moved, double) { return sign * moved >= o_.ramp_distance_m; });
    record.steps.back().ramp_rate_per_s = o_.ramp_rate_per_s;
    const double reference = reference_length_m_;
    Rest();
    start_duty[sign > 0 ? 0 : 1] =
        RampStartDuty(record, record.steps[record.steps.size() - 2], reference, o_.ramp_rate_per_s)
            .duty;
  }
  double lowest_level = o_.max_duty;
  for (const DutyLevels& levels : o_.levels) lowest_level = std::min(lowest_level, levels.lo);
  const double start = std::max(start_duty[0], start_duty[1]);
  if (lowest_level < start + o_.level_margin_duty) {
    Fail(LegName() + " starts to move only at duty " + Fmt("%.3f", start) +
         ": the excursions' lowest level " + Fmt("%.2f", lowest_level) + " must be at least " +
         Fmt("%.2f", o_.level_margin_duty) + " above it (raise the levels)");
  }

  // Excursions: out by excursion_m, back home.
  int excursion = 0;
  for (int r = 0; r < o_.repeats; ++r) {
    for (std::size_t j = 0; j < o_.levels.size(); ++j) {
      const DutyLevels levels = o_.levels[j];
      const int sign = j % 2 == 0 ? 1 : -1;
      const int out = excursion++;
      RunStep(
          StepKind::kExcursion, sign, o_.move_timeout_s,
          [this, sign, levels, out](double elapsed_s) {
            return sign * SquareWave(levels, elapsed_s, out);
          },
          [this, sign](double, double moved, double) { return sign * moved >= o_.excursion_m; });
      record.steps.back().levels = levels;
      Rest();
      const int back = excursion++;
      RunStep(
          StepKind::kExcursion, -sign, o_.move_timeout_s,
          [this, sign, levels, back](double elapsed_s) {
            return -sign * SquareWave(levels, elapsed_s, back);
          },
          [sign, home](double, double, double length) { return -sign * (length - home) >= 0.0; });
      record.steps.back().levels = levels;
      Rest();
    }
  }
  const double duration_s =
      static_cast<double>(record.samples.back().utime - record.samples.front().utime) * 1e-6;
  Report(LegName() + ": home " + Fmt("%.4f", home) + " m, starts to move at duty +" +
         Fmt("%.3f", start_duty[0]) + " / -" + Fmt("%.3f", start_duty[1]) + ", " +
         std::to_string(2 * o_.levels.size() * static_cast<std::size_t>(o_.repeats)) +
         " excursions, " + Fmt("%.1f", duration_s) + " s");
  record_ = nullptr;
  return record;
}

}  // namespace

const char* ToString(StepKind kind) {
  switch (kind) {
    case StepKind::kRest:
      return "rest";
    case StepKind::kDirectionCheck:
      return "direction check";
    case StepKind::kReturn:
      return "return";
    case StepKind::kRamp:
      return "start ramp";
    case StepKind::kExcursion:
      return "excursion";
  }
  return "step";
}

GuardTrip::GuardTrip(int leg_index, hw::GuardReason why, double length, double speed,
                     int64_t at_utime, const std::string& message)
    : std::runtime_error(message),
      leg(leg_index),
      reason(why),
      length_m(length),
      speed_mps(speed),
      utime(at_utime) {}

void ValidateProcedureOptions(const ActuatorProcedureOptions& o) {
  const auto fail = [](const std::string& what) { throw IdentificationError(what); };
  if (o.legs.empty()) fail("no leg to identify");
  std::set<int> seen;
  for (const int leg : o.legs) {
    if (leg < 0 || leg >= kNumLegs) fail("leg " + std::to_string(leg) + " is not 0..5");
    if (!seen.insert(leg).second) fail("leg " + std::to_string(leg) + " given twice");
  }
  if (!(o.max_duty > 0.0 && o.max_duty <= 1.0)) fail("max duty must be in (0, 1]");
  if (o.levels.empty()) fail("no excursion levels");
  for (const DutyLevels& l : o.levels) {
    if (!(l.lo > 0.0 && l.lo < l.hi && l.hi <= o.max_duty)) {
      fail("excursion levels must satisfy 0 < lo < hi <= max duty (got " + Fmt("%g", l.hi) + ", " +
           Fmt("%g", l.lo) + ")");
    }
  }
  const double positive[] = {o.rest_s,          o.check_duty,         o.check_distance_m,
                             o.ramp_rate_per_s, o.ramp_max_duty,      o.ramp_distance_m,
                             o.half_period_s,   o.excursion_m,        o.move_timeout_s,
                             o.guard.margin_m,  o.guard.speed_cap_mps};
  for (const double v : positive) {
    if (!(v > 0.0 && std::isfinite(v))) fail("procedure times, distances and duties must be > 0");
  }
  if (o.check_duty > o.max_duty || o.ramp_max_duty > o.max_duty) {
    fail("check and ramp duties must not exceed the max duty");
  }
  if (o.repeats < 1) fail("repeats must be >= 1");
  const double stroke_m = o.guard.max_length_m - o.guard.min_length_m;
  if (!(stroke_m > 2.0 * (o.guard.margin_m + o.excursion_m))) {
    fail("the excursion (" + Fmt("%g", o.excursion_m) + " m) and the guard margin do not fit " +
         "in the stroke");
  }
}

ActuatorRecord RunActuatorProcedure(ActuatorDevice* device, const ActuatorProcedureOptions& options,
                                    const ProgressFn& progress) {
  ValidateProcedureOptions(options);
  Runner runner(device, options, progress);
  ActuatorRecord record;
  try {
    for (const int leg : options.legs) {
      record.legs.push_back(runner.RunLeg(leg));
      const LegTestRecord& r = record.legs.back();
      record.samples += static_cast<long>(r.samples.size());
      record.duration_s +=
          static_cast<double>(r.samples.back().utime - r.samples.front().utime) * 1e-6;
    }
  } catch (...) {
    runner.SendZero();
    throw;
  }
  runner.SendZero();
  return record;
}

}  // namespace stewart::identify
