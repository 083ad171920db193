#pragma once
// The simulated platform: plant state, zero-order-hold inputs and the
// SUNDIALS integration between control ticks (docs/simulation.md).
#include <array>
#include <memory>

#include "stewart/plant_sim/ode_integrator.h"
#include "stewart/plant_sim/plant_dynamics.h"

namespace stewart {

struct PlantCounters {
  long endstop_hits = 0;  ///< times a leg entered an end-stop (stroke end crossed outwards)
  long delayed_commands_dropped = 0;  ///< applied early: the delay queue was full
  /// Intervals the explicit integrator failed on (stiff end-stop chatter)
  /// and the implicit BDF fallback integrated instead.
  long stiff_fallbacks = 0;
  /// DC motor: times a leg's self-locking screw took hold of it.
  long self_lock_engagements = 0;
  OdeStats ode;
};

class Plant {
 public:
  Plant(const PlantModel& model, const OdeOptions& ode_options);

  /// Restarts at time t_s (s) in state (q, qd) with zero motor force and the
  /// actuators on.
  void Reset(double t_s, const Vector6d& q, const Vector6d& qd);

  /// Zero-order hold: the command acts from now + model().command_delay_s
  /// until the next change takes effect. A change restarts the integrator,
  /// since f(x) jumps.
  /// A DC-motor plant turns the force into a duty by model().duty_map (the
  /// driver plant_sim stands in for) and holds that.
  void SetForceCommand(const Vector6d& force_cmd_n);
  /// DC motor only (throws std::logic_error otherwise): the PWM duty per leg,
  /// as the device receives it. Held and delayed like a force command.
  void SetDutyCommand(const Vector6d& duty);
  /// Actuators off: zero force, and the lead screws hold every leg at its
  /// length at this instant (LegLockForce; a DC motor's legs self-lock one by
  /// one as they stop); drops commands not yet in effect. Restarts the
  /// integrator on change.
  /// Actuators on again: the drive returns with the next command, so under a
  /// command delay the legs stay held until that command takes effect (the
  /// real drive gets both through the same link; releasing at once left the
  /// legs unpowered and free for the delay, a platform's free fall).
  void SetActuatorsOff(bool off);
  /// External wrench from now on ([N; N m] in {B}, PlantInputs).
  void SetExternalWrench(const Vector6d& wrench);

  /// Integrates the held inputs over dt_s (s), switching to each delayed
  /// command at its time. Stops and restarts at every stroke-end crossing
  /// (the end-stop force is not smooth there), counting entries into an
  /// end-stop. When the explicit integrator fails (a leg chattering in a
  /// stiff end-stop can drive its step to the minimum), the interval is
  /// integrated again from its start by CVODE BDF, which stiffness does not
  /// stall (counted: counters().stiff_fallbacks). Throws std::runtime_error
  /// if that fails too.
  void Advance(double dt_s);

  double time_s() const { return t_s_; }
  Vector6d q() const { return PoseOf(x_); }
  Vector6d qd() const { return VelocityOf(x_); }
  const PlantStateVector& state() const { return x_; }
  const PlantInputs& inputs() const { return inputs_; }
  bool actuators_off() const { return inputs_.legs_locked; }
  const PlantModel& model() const { return model_; }

  /// Right-hand side at the current state with the inputs held now
  /// (acceleration qdd, total leg forces, model terms). Free right after
  /// Advance: the integrator's last evaluation was at this state.
  const PlantRates& EvaluateRates();
  /// True iff a leg is now beyond either stroke end (inside an end-stop).
  bool InEndStop() const;
  PlantCounters counters() const;

 private:
  struct DelayedCommand {
    double apply_s;
    Vector6d command;       // force (N) or, for a DC motor, duty
    bool releases = false;  // the drive returns with it (SetActuatorsOff(false))
  };
  // Room for 0.5 s of delay at 1 kHz: far beyond any latency worth simulating.
  static constexpr int kDelayCapacity = 512;

  void QueueCommand(const Vector6d& command);
  void ApplyDelayed(const DelayedCommand& delayed);
  void ReleaseLegs();
  // Force (ideal source) or duty (DC motor) from now on.
  void ApplyCommand(const Vector6d& command);
  // DC motor: which legs the self-locking screws hold, judged at the state
  // now (between integration intervals): a leg whose motor is not energised
  // is taken hold of once its speed falls below kHoldSpeedMps or the load
  // on it is below the back-drive force (UndrivenLoadEstimateN), and let go
  // when the motor is energised or its spring carries more than the
  // back-drive force.
  void UpdateSelfLocking();
  // The axial load on each leg were its motor not energised, as its motion
  // shows it (N): the smoothed resistance at its speed plus the rotor's
  // mass times its acceleration away from rest.
  Vector6d UndrivenLoadEstimateN(const Vector6d& leg_length_m, const Vector6d& leg_speed_mps,
                                 const Vector6d& leg_accel_mps2) const;
  void IntegrateTo(double t_end);
  // The integration loop of IntegrateTo with `integrator`, from (t_s_, x_);
  // throws as OdeIntegrator::Advance does.
  void IntegrateWith(OdeIntegrator* integrator, double t_end);
  static int Rhs(double t, const double* y, double* y_dot, void* self);
  static int Roots(double t, const double* y, double* g, void* self);
  // A change of the held inputs or a stroke-end crossing: restart, and
  // rates_ must be recomputed for the inputs (not for the model terms).
  void MarkDiscontinuity() {
    restart_pending_ = true;
    ++inputs_revision_;
  }
  // f(x) with the held inputs into rates_, reusing what rates_ holds. ARKODE
  // evaluates f at the end of every step (its next first stage), so after a
  // tick rates_ holds f at x_: EvaluateRates then costs nothing, and the
  // restart at the next tick, where only the force changes, keeps the model
  // terms (M, C qd, G, H), which depend on q and qd alone; the root
  // functions then reuse their leg lengths.
  const PlantRates& UpdateRates(const PlantStateVector& x);

  PlantModel model_;
  // Integrated values: q, qd and, only with a force lag, F_motor (without
  // one, F_motor = sat(F_cmd) is an input and stays in x_ for output only).
  int ode_size_;
  OdeIntegrator integrator_;
  OdeOptions ode_options_;
  std::unique_ptr<OdeIntegrator> stiff_;  // made on the first failure of integrator_
  long stiff_fallbacks_ = 0;
  PlantInputs inputs_;
  PlantStateVector x_ = PlantStateVector::Zero();
  double t_s_ = 0.0;
  bool restart_pending_ = true;
  long endstop_hits_ = 0;
  long self_lock_engagements_ = 0;
  long inputs_revision_ = 0;
  std::array<DelayedCommand, kDelayCapacity> delayed_{};  // ring, in time order
  int delayed_head_ = 0;
  int delayed_count_ = 0;
  long delayed_dropped_ = 0;
  bool release_pending_ = false;  // SetActuatorsOff(false) waits for the next command
  PlantRates rates_;              // f at rates_x_ under rates_revision_; no allocation per call
  PlantStateVector rates_x_ = PlantStateVector::Zero();
  long rates_revision_ = -1;  // -1: rates_ holds nothing yet
};

}  // namespace stewart
