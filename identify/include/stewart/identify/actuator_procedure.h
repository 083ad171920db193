#pragma once
// The bring-up identification run of the DC-motor legs (docs/hardware.md,
// "Identify the actuators"): one leg at a time, the other five at zero duty
// (their self-locking screws hold them), against an ActuatorDevice.
//
// Per leg, from where the platform is (normally home):
//   1. rest: zero duty, the screws take hold; the leg's home length;
//   2. direction check: +check_duty until the leg has extended
//      check_distance_m (a leg that retracts instead has a reversed drive;
//      one that does not move is unpowered, unplugged or blocked); back;
//   3. start ramps: |duty| rising at ramp_rate_per_s from 0 until the leg has
//      moved ramp_distance_m, extending, then retracting: the duty at which
//      it starts to move;
//   4. excursions: per pair of levels (hi, lo), a square wave of the duty
//      between them (half periods 0.75-1.25 half_period_s, irregular) in one
//      direction until the
//      leg has moved excursion_m, a rest, and the same back to its home
//      length; pairs alternate between starting outwards and inwards, so the
//      leg stays within +-excursion_m of home.
// A rest of rest_s separates every move. Every sample goes through the leg
// guard (hw_bridge/leg_guard.h): a leg that comes within the margin of a
// stroke end, is faster than the cap or reads badly gets zero duty at once
// (all legs do) and the run ends with GuardTrip. Moves stop on distance, not
// on time, so a motor faster or slower than the config's cannot carry a leg
// further; a move that does not cover its distance in move_timeout_s ends
// the run (IdentificationError).
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "stewart/hw_bridge/leg_guard.h"
#include "stewart/identify/actuator_device.h"
#include "stewart/identify/inertial_fit.h"

namespace stewart::identify {

/// The duty levels of one excursion: a square wave between hi and lo (both
/// > 0; the direction gives the sign).
struct DutyLevels {
  double hi = 1.0;
  double lo = 0.3;
};

struct ActuatorProcedureOptions {
  std::vector<int> legs = {0, 1, 2, 3, 4, 5};
  hw::LegGuardLimits guard;  ///< stroke ends, margin, speed cap
  double max_duty = 1.0;     ///< |duty| is clamped to this
  double rest_s = 0.2;
  double check_duty = 0.6;
  double check_distance_m = 1e-3;
  double ramp_rate_per_s = 0.1;
  double ramp_max_duty = 0.6;
  double ramp_distance_m = 1e-3;
  /// Deep steps carry the rotor's lag (the fit's kappa) and the speed / duty
  /// line; 0.1 s half periods are ~10 rotor time constants, so each level
  /// settles (shorter ones measured worse, 0.03 s: sigma(m_r) 2.9 % against
  /// 1.6 %).
  std::vector<DutyLevels> levels = {{1.0, 0.3}, {0.8, 0.3}, {1.0, 0.5}, {0.6, 0.3}};
  double half_period_s = 0.1;
  double excursion_m = 0.008;
  int repeats = 1;  ///< the excursions, this many times
  /// The lowest level must lie this far above the duty the leg starts at
  /// (ramps): below it the motor is not energised and the fit's model is not
  /// the leg's.
  double level_margin_duty = 0.1;
  double move_timeout_s = 5.0;
};

/// Checks the options (legs 0..5 without repeats, levels in (0, max_duty],
/// distances and times positive, excursion inside the stroke with margin);
/// throws IdentificationError naming the option.
void ValidateProcedureOptions(const ActuatorProcedureOptions& options);

enum class StepKind { kRest, kDirectionCheck, kReturn, kRamp, kExcursion };
const char* ToString(StepKind kind);

/// One step of a leg's test: samples [first_sample, end_sample) of its record.
struct ProcedureStep {
  StepKind kind = StepKind::kRest;
  int sign = 0;  ///< +1 extends, -1 retracts, 0 rest
  DutyLevels levels;
  double ramp_rate_per_s = 0.0;
  std::size_t first_sample = 0;
  std::size_t end_sample = 0;
  double moved_m = 0.0;  ///< signed length change over the step
};

/// Everything one leg's test recorded.
struct LegTestRecord {
  int leg = 0;
  double home_length_m = 0.0;  ///< mean over the first rest
  std::vector<ActuatorSample> samples;
  std::vector<ProcedureStep> steps;
};

struct ActuatorRecord {
  std::vector<LegTestRecord> legs;
  long samples = 0;
  double duration_s = 0.0;
};

/// The guard stopped the run. what(): one line naming the leg, the reason,
/// its length and speed and the time.
class GuardTrip : public std::runtime_error {
 public:
  GuardTrip(int leg, hw::GuardReason reason, double length_m, double speed_mps, int64_t utime,
            const std::string& message);
  int leg;
  hw::GuardReason reason;
  double length_m;
  double speed_mps;
  int64_t utime;
};

using ProgressFn = std::function<void(const std::string& line)>;

/// Runs the procedure. On return every leg has zero duty. Throws GuardTrip,
/// or IdentificationError for bad samples (non-finite, flagged, time going
/// backwards), a reversed or unmoving leg, a timeout, or levels too close to
/// the start duty; zero duty is sent before either is thrown.
ActuatorRecord RunActuatorProcedure(ActuatorDevice* device, const ActuatorProcedureOptions& options,
                                    const ProgressFn& progress = {});

}  // namespace stewart::identify
