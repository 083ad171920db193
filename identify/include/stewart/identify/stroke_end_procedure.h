#pragma once
// The pot calibration's bring-up run (docs/hardware.md, "Calibrate the pots
// at the stroke ends"): all six legs together to their retracted ends, back,
// to their extended ends, back, against an ActuatorDevice, recording each
// leg's reading where its lead screw stops at the end of its stroke. Those
// two readings per leg are where the leg's length is known from the
// actuator's data (actuators.min_length_m and + stroke_m), so they give the
// two-point calibration (pot_calibration.h).
//
// One leg alone cannot reach its ends with the platform on (a leg at home is
// 35 mm from its retracted end and 165 mm from its extended one; the other
// five held, the platform would leave its workspace long before). All six
// together move the platform up and down, about level: every leg follows
// its own reference r_i(t) = L0_i + s p(t), with L0_i its length at rest,
// s = -1 towards the retracted ends and +1 towards the extended ones, and a
// common path p(t) at travel_speed_mps, slowed to approach_speed_mps where a
// leg comes within slow_zone_m of its nominal end, through the end by up to
// search_m:
//   duty_i = clamp(s u(v) + gain (r_i - L_i), -cap, cap)
// with u(v) the config motor's duty for its back-EMF force at speed v, cap
// max_duty in travel and push_duty in the slow zone: a leg at its end stop
// falls behind its reference and pushes into the stop with at most
// push_duty, while the others catch up. The end is reached when every leg,
// pulled on by its reference, has stayed within stall_band_m for stall_s.
// The reading is then averaged over the second half of hold_s, pushing with
// at most hold_duty (the end stop's compliance under that push is in it:
// about 0.05 mm in the simulator, 2e5 N/m under ~10 N; 0.15-0.2 mm under
// push_duty).
//
// The run stops with zero duty (IdentificationError) when a leg falls more
// than max_lag_m behind the others before its slow zone (blocked, or not
// driven), stops outside [nominal end - stop_window_m, nominal end +
// search_m], or a move takes longer than move_timeout_s; and with GuardTrip
// when the guard (the bring-up guard with its end zones search_m beyond the
// nominal ends, hw_bridge/bringup.h StrokeEndSearchGuard) trips.
#include <functional>
#include <string>

#include "stewart/hw_bridge/leg_guard.h"
#include "stewart/identify/actuator_device.h"
#include "stewart/identify/actuator_procedure.h"
#include "stewart/model/actuator_params.h"

namespace stewart::identify {

struct StrokeEndOptions {
  double min_length_m = 0.0;  ///< nominal stroke ends (joint to joint), the config's
  double max_length_m = 0.0;
  double search_m = 0.004;       ///< how far beyond a nominal end a reading may go
  double stop_window_m = 0.010;  ///< how far before a nominal end a leg may stop
  double slow_zone_m = 0.010;
  double travel_speed_mps = 0.010;
  double approach_speed_mps = 0.003;
  double max_duty = 1.0;
  double push_duty = 0.3;
  double hold_duty = 0.15;
  double gain_duty_per_m = 200.0;
  double max_lag_m = 0.005;
  double stall_band_m = 2.5e-4;  ///< a leg within this of its last position has not moved
  double stall_s = 0.3;
  double hold_s = 0.5;
  double rest_s = 0.3;
  double move_timeout_s = 60.0;
  double speed_cap_mps = 0.05;  ///< the guard's
  DcMotorParams motor;          ///< the config's, for the duty's feed-forward
};

/// Throws IdentificationError naming the option.
void ValidateStrokeEndOptions(const StrokeEndOptions& options);

/// The guard the run (and hw_bridge --bringup-end-search) uses: end zones
/// search_m beyond the nominal ends, half a millimetre wide.
hw::LegGuardLimits StrokeEndGuard(const StrokeEndOptions& options);

struct StrokeEndRecord {
  Vector6d home_length_m = Vector6d::Zero();        ///< at rest before the run (readings)
  Vector6d retracted_reading_m = Vector6d::Zero();  ///< mean reading at the retracted end
  Vector6d extended_reading_m = Vector6d::Zero();
  Vector6d retracted_std_m = Vector6d::Zero();  ///< the readings' std over the hold
  Vector6d extended_std_m = Vector6d::Zero();
  long samples = 0;
  double duration_s = 0.0;
};

/// Runs it from where the platform is (normally home, at rest) and brings
/// it back there. On return every leg has zero duty. Throws GuardTrip or
/// IdentificationError (bad samples, a lagging or blocked leg, a stop
/// outside the window, a timeout); zero duty is sent before either.
StrokeEndRecord RunStrokeEndProcedure(ActuatorDevice* device, const StrokeEndOptions& options,
                                      const ProgressFn& progress = {});

}  // namespace stewart::identify
