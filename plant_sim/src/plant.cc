#include "stewart/plant_sim/plant.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "stewart/model/kinematics.h"
#include "stewart/plant_sim/actuator_model.h"

namespace stewart {
namespace {

// Root functions: g_i = L_i - l_min and g_{6+i} = l_max - L_i; a falling
// zero crossing means a leg enters an end-stop.
constexpr int kNumRoots = 2 * kNumLegs;
// A segment that keeps stopping at roots without reaching its end is a
// chattering contact; far more than any real impact sequence in one tick.
constexpr int kMaxRootStopsPerAdvance = 10000;

// Without force lag F_motor has rate 0: integrating it would only add six
// constants to every vector operation and to the error norm.
constexpr int kMotionStateSize = 12;

// DC motor: a leg slower than this with its motor not energised is taken
// hold of by its self-locking screw (m/s; a tenth of the dry friction's
// smoothing speed). Faster legs are caught once the load on them is below
// the back-drive force (Plant::UpdateSelfLocking).
constexpr double kHoldSpeedMps = 1e-4;

int OdeSizeFor(const ActuatorConfig& actuators) {
  return actuators.force_lag_s > 0.0 ? kPlantStateSize : kMotionStateSize;
}

}  // namespace

Plant::Plant(const PlantModel& model, const OdeOptions& ode_options)
    : model_(model),
      ode_size_(OdeSizeFor(model.actuators)),
      integrator_(ode_options, ode_size_, kNumRoots, &Plant::Rhs, &Plant::Roots, this),
      ode_options_(ode_options) {}

void Plant::Reset(double t_s, const Vector6d& q, const Vector6d& qd) {
  t_s_ = t_s;
  x_.setZero();
  x_.segment<6>(0) = q;
  x_.segment<6>(6) = qd;
  inputs_ = PlantInputs{};
  endstop_hits_ = 0;
  self_lock_engagements_ = 0;
  delayed_head_ = delayed_count_ = 0;
  release_pending_ = false;
  MarkDiscontinuity();
}

void Plant::SetForceCommand(const Vector6d& force_cmd_n) {
  QueueCommand(model_.actuators.kind == ActuatorKind::kDcMotor
                   ? DutyForForce(model_.duty_map, force_cmd_n)
                   : force_cmd_n);
}

void Plant::SetDutyCommand(const Vector6d& duty) {
  if (model_.actuators.kind != ActuatorKind::kDcMotor) {
    throw std::logic_error("Plant::SetDutyCommand: the actuators are not DC motors");
  }
  QueueCommand(duty.unaryExpr([](double d) { return std::isfinite(d) ? d : 0.0; })
                   .cwiseMax(-1.0)
                   .cwiseMin(1.0));
}

void Plant::QueueCommand(const Vector6d& command) {
  if (!(model_.command_delay_s > 0.0)) {
    ApplyCommand(command);
    return;
  }
  if (delayed_count_ == kDelayCapacity) {
    ApplyDelayed(delayed_[static_cast<size_t>(delayed_head_)]);
    delayed_head_ = (delayed_head_ + 1) % kDelayCapacity;
    --delayed_count_;
    ++delayed_dropped_;
  }
  const int tail = (delayed_head_ + delayed_count_) % kDelayCapacity;
  delayed_[static_cast<size_t>(tail)] =
      DelayedCommand{t_s_ + model_.command_delay_s, command, release_pending_};
  release_pending_ = false;
  ++delayed_count_;
}

void Plant::ApplyDelayed(const DelayedCommand& delayed) {
  if (delayed.releases) ReleaseLegs();
  ApplyCommand(delayed.command);
}

void Plant::ReleaseLegs() {
  if (!inputs_.legs_locked) return;
  inputs_.legs_locked = false;
  MarkDiscontinuity();
}

void Plant::SetExternalWrench(const Vector6d& wrench) {
  if (wrench == inputs_.external_wrench) return;
  inputs_.external_wrench = wrench;
  MarkDiscontinuity();
}

void Plant::ApplyCommand(const Vector6d& command) {
  const bool dc_motor = model_.actuators.kind == ActuatorKind::kDcMotor;
  Vector6d& held = dc_motor ? inputs_.duty : inputs_.force_cmd_n;
  if (command == held) return;
  held = command;
  if (!(model_.actuators.force_lag_s > 0.0)) {
    // Without lag the motor force is the saturated command; the state keeps it for output.
    x_.segment<6>(12) = model_.actuator_errors.force_gain.cwiseProduct(
        dc_motor ? DcMotorDriveForce(model_.actuators.motor, command, inputs_.legs_locked)
                 : SaturateForce(model_.actuators, command));
  }
  MarkDiscontinuity();
}

void Plant::UpdateSelfLocking() {
  if (model_.actuators.kind != ActuatorKind::kDcMotor) return;
  const DcMotorParams& motor = model_.actuators.motor;
  const PlantRates& rates = EvaluateRates();
  const Vector6d leg_speed_mps = rates.terms.H.transpose() * qd();
  const Vector6d& leg_length_m = rates.terms.leg_length_m;
  const double c_hold = DcMotorHoldDampingNspm(motor);
  // Ldd = H^T qdd + Jdot_l qd (m/s^2): with the speed, it tells a leg that
  // friction is slowing from one its load drives on.
  const Vector6d leg_accel_mps2 =
      rates.terms.H.transpose() * rates.x_dot.segment<6>(6) + rates.terms.leg_bias_accel_mps2;
  const Vector6d undriven_load_n =
      UndrivenLoadEstimateN(leg_length_m, leg_speed_mps, leg_accel_mps2);
  bool changed = false;
  for (int i = 0; i < kNumLegs; ++i) {
    bool& held = inputs_.leg_held[static_cast<size_t>(i)];
    const bool energised = DcMotorEnergised(motor, inputs_.duty(i), inputs_.legs_locked);
    bool hold = held;
    if (energised) {
      hold = false;
    } else if (held) {
      const double spring_n =
          motor.lock_stiffness_npm * (leg_length_m(i) - inputs_.hold_length_m(i)) +
          c_hold * leg_speed_mps(i);
      hold = std::abs(spring_n) <= motor.back_drive_force_n;
    } else if (std::abs(leg_speed_mps(i)) < kHoldSpeedMps ||
               undriven_load_n(i) < motor.back_drive_force_n) {
      hold = true;
      // The spring starts at the length where it carries nothing at this
      // speed, k (L_held - L) = c Ld: the leg force stays continuous (no
      // catch impulse) and the leg stops a few micrometres on.
      inputs_.hold_length_m(i) =
          leg_length_m(i) + c_hold * leg_speed_mps(i) / motor.lock_stiffness_npm;
      ++self_lock_engagements_;
    }
    if (hold != held) {
      held = hold;
      changed = true;
    }
  }
  if (changed) MarkDiscontinuity();
}

Vector6d Plant::UndrivenLoadEstimateN(const Vector6d& leg_length_m, const Vector6d& leg_speed_mps,
                                      const Vector6d& leg_accel_mps2) const {
  // The smoothed dry friction lets a leg loaded below the back-drive force
  // creep at the speed where the smoothed force meets the load; the screw
  // would stop it. The load is the resistance at this speed plus what
  // accelerates the leg onwards (the rotor's mass, the least the leg
  // carries): one that friction is slowing, or that creeps steadily, is
  // under its resistance; one driven on faster is not caught.
  const Vector6d resistance_n =
      DcMotorUndrivenResistanceN(model_.actuators, model_.actuator_errors.coulomb_friction_n,
                                 inputs_.legs_locked, leg_length_m, leg_speed_mps);
  const Vector6d onward_accel_mps2 = leg_accel_mps2.cwiseProduct(leg_speed_mps.cwiseSign());
  return resistance_n + model_.actuators.motor.reflected_mass_kg * onward_accel_mps2.cwiseMax(0.0);
}

void Plant::SetActuatorsOff(bool off) {
  if (!off) {
    if (model_.command_delay_s > 0.0) {
      release_pending_ = inputs_.legs_locked;
    } else {
      ReleaseLegs();
    }
    return;
  }
  release_pending_ = false;
  if (inputs_.legs_locked) return;
  inputs_.legs_locked = true;
  inputs_.lock_length_m = InverseKinematics(model_.platform, q());
  delayed_head_ = delayed_count_ = 0;
  ApplyCommand(Vector6d::Zero());
  MarkDiscontinuity();
}

void Plant::Advance(double dt_s) {
  if (!(dt_s > 0.0)) throw std::invalid_argument("Plant::Advance: dt_s must be positive");
  const double t_end = t_s_ + dt_s;
  while (delayed_count_ > 0 && delayed_[static_cast<size_t>(delayed_head_)].apply_s < t_end) {
    const DelayedCommand& next = delayed_[static_cast<size_t>(delayed_head_)];
    if (next.apply_s > t_s_) IntegrateTo(next.apply_s);
    ApplyDelayed(next);
    delayed_head_ = (delayed_head_ + 1) % kDelayCapacity;
    --delayed_count_;
  }
  IntegrateTo(t_end);
}

void Plant::IntegrateTo(double t_end) {
  UpdateSelfLocking();
  const double t_start = t_s_;
  const PlantStateVector x_start = x_;
  const long hits_start = endstop_hits_;
  try {
    IntegrateWith(&integrator_, t_end);
    return;
  } catch (const std::runtime_error&) {
    if (ode_options_.method == OdeMethod::kCvodeBdf) throw;
  }
  // The explicit method gave up (step at its minimum): the whole interval
  // again, from its start, implicitly. Tolerances stay the configured ones.
  t_s_ = t_start;
  x_ = x_start;
  endstop_hits_ = hits_start;
  if (!stiff_) {
    OdeOptions stiff_options = ode_options_;
    stiff_options.method = OdeMethod::kCvodeBdf;
    stiff_ = std::make_unique<OdeIntegrator>(stiff_options, ode_size_, kNumRoots, &Plant::Rhs,
                                             &Plant::Roots, this);
  }
  ++stiff_fallbacks_;
  MarkDiscontinuity();
  IntegrateWith(stiff_.get(), t_end);
  MarkDiscontinuity();  // the next interval starts the explicit method afresh
}

void Plant::IntegrateWith(OdeIntegrator* integrator, double t_end) {
  std::array<int, kNumRoots> roots_found{};
  for (int stops = 0;; ++stops) {
    if (stops > kMaxRootStopsPerAdvance) {
      throw std::runtime_error(
          "plant integration chatters at a stroke end at t = " + std::to_string(t_s_) + " s");
    }
    if (restart_pending_) {
      integrator->Reinit(t_s_, x_.data());
      restart_pending_ = false;
    }
    double t_reached = t_s_;
    const OdeIntegrator::Result result =
        integrator->Advance(t_end, x_.data(), &t_reached, roots_found.data());
    t_s_ = t_reached;
    if (result == OdeIntegrator::Result::kReachedTime) break;
    for (int i = 0; i < kNumRoots; ++i) {
      if (roots_found[static_cast<size_t>(i)] < 0) ++endstop_hits_;
    }
    MarkDiscontinuity();
  }
  t_s_ = t_end;  // the stop time is hit exactly; avoid any drift of the tick grid
}

const PlantRates& Plant::EvaluateRates() { return UpdateRates(x_); }

const PlantRates& Plant::UpdateRates(const PlantStateVector& x) {
  // Exact equality: the cached values are those a new evaluation would give.
  const bool same_motion =
      rates_revision_ >= 0 && x.head<kMotionStateSize>() == rates_x_.head<kMotionStateSize>();
  if (same_motion && rates_revision_ == inputs_revision_ &&
      MotorForceOf(x) == MotorForceOf(rates_x_)) {
    return rates_;
  }
  if (!same_motion) EvaluateDynamics(model_.platform, PoseOf(x), VelocityOf(x), &rates_.terms);
  PlantDerivativeGivenTerms(model_, inputs_, x, &rates_);
  rates_x_ = x;
  rates_revision_ = inputs_revision_;
  return rates_;
}

bool Plant::InEndStop() const {
  const Vector6d lengths = InverseKinematics(model_.platform, q());
  const double l_min = model_.actuators.min_length_m;
  const double l_max = l_min + model_.actuators.stroke_m;
  return (lengths.array() < l_min).any() || (lengths.array() > l_max).any();
}

PlantCounters Plant::counters() const {
  PlantCounters c;
  c.endstop_hits = endstop_hits_;
  c.delayed_commands_dropped = delayed_dropped_;
  c.stiff_fallbacks = stiff_fallbacks_;
  c.self_lock_engagements = self_lock_engagements_;
  c.ode = integrator_.stats();
  return c;
}

int Plant::Rhs(double /*t*/, const double* y, double* y_dot, void* self) {
  auto* plant = static_cast<Plant*>(self);
  using MotionVector = Eigen::Matrix<double, kMotionStateSize, 1>;
  const bool motion_only = plant->ode_size_ == kMotionStateSize;
  PlantStateVector x;
  if (motion_only) {
    x << Eigen::Map<const MotionVector>(y), MotorForceOf(plant->x_);
  } else {
    x = Eigen::Map<const PlantStateVector>(y);
  }
  const PlantRates& rates = plant->UpdateRates(x);
  if (!rates.x_dot.allFinite()) return 1;  // recoverable: retry a smaller step
  if (motion_only) {
    Eigen::Map<MotionVector> x_dot(y_dot);
    x_dot = rates.x_dot.head<kMotionStateSize>();
  } else {
    Eigen::Map<PlantStateVector> x_dot(y_dot);
    x_dot = rates.x_dot;
  }
  return 0;
}

int Plant::Roots(double /*t*/, const double* y, double* g, void* self) {
  const auto* plant = static_cast<const Plant*>(self);
  const Vector6d q = Eigen::Map<const Vector6d>(y);
  // ARKODE checks the roots right after evaluating f at the same state; the
  // model's leg lengths are bit-identical to InverseKinematics.
  const Vector6d lengths = plant->rates_revision_ >= 0 && q == plant->rates_x_.head<6>()
                               ? plant->rates_.terms.leg_length_m
                               : InverseKinematics(plant->model_.platform, q);
  const double l_min = plant->model_.actuators.min_length_m;
  const double l_max = l_min + plant->model_.actuators.stroke_m;
  Eigen::Map<Vector6d> g_low(g);
  Eigen::Map<Vector6d> g_high(g + kNumLegs);
  g_low = lengths.array() - l_min;
  g_high = l_max - lengths.array();
  return 0;
}

}  // namespace stewart
