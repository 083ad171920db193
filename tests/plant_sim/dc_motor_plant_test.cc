// The DC-motor leg (P-16P class behind an L298N) in plant_sim's library: its
// input map, the no-load speed and stall force it gives, the self-locking
// screw, the power balance and the integration against a fine reference.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cmath>

#include "plant_test_util.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/kinematics.h"
#include "stewart/plant_sim/actuator_model.h"
#include "stewart/plant_sim/plant_dynamics.h"

namespace stewart {
namespace {

using test::Config;

// The default config's legs as DC motors (its `actuators.motor` values).
PlantModel DcMotorModel() {
  PlantModel model = test::DefaultModel();
  model.actuators.kind = ActuatorKind::kDcMotor;
  model.platform.leg.actuator_reflected_mass_kg = model.actuators.motor.reflected_mass_kg;
  model.duty_map = PlantModel::DriverOf(model.actuators);
  return model;
}

Vector6d LegSpeed(const Plant& plant) {
  return LegLengthJacobian(plant.model().platform, plant.q()) * plant.qd();
}

TEST(DcMotorMap, DutyAndDriveForceAreInverse) {
  const DcMotorParams& m = Config().actuators.motor;
  const double f_full = DcMotorForceAtFullDuty(m);
  EXPECT_NEAR(f_full, m.stall_force_n * (m.supply_voltage_v - m.bridge_drop_v) / m.rated_voltage_v,
              1e-12);
  EXPECT_EQ(DcMotorDriveForce(m, 0.5 * m.dead_band_duty), 0.0);  // inside the dead band
  EXPECT_EQ(DcMotorDriveForce(m, -m.dead_band_duty), 0.0);
  EXPECT_NEAR(DcMotorDriveForce(m, 1.0), f_full, 1e-12);
  EXPECT_NEAR(DcMotorDriveForce(m, -7.0), -f_full, 1e-12);  // clamped to |duty| <= 1
  EXPECT_EQ(DcMotorDriveForce(m, NAN), 0.0);
  for (double f : {-f_full, -30.0, -0.01, 0.0, 0.01, 2.5, 80.0, f_full}) {
    EXPECT_NEAR(DcMotorDriveForce(m, DcMotorDutyForDriveForce(m, f)), f, 1e-9 * f_full) << f;
  }
  EXPECT_EQ(DcMotorDutyForDriveForce(m, NAN), 0.0);
  EXPECT_EQ(DcMotorDutyForDriveForce(m, 1e300), 1.0);
}

// Every leg at the same duty, no gravity and no dry friction: the legs have
// no load but the platform's inertia, so each settles at the speed where the
// drive force meets the back-EMF and screw damping,
// Ld = u_eff F_full / (b_emf + b_screw): v_noload (V_s - V_drop) / V_rated at
// full duty, linear in u_eff, zero inside the dead band.
TEST(DcMotorLeg, NoLoadSpeedFollowsTheDuty) {
  PlantModel model = DcMotorModel();
  model.platform.gravity_mps2 = 0.0;
  model.actuators.motor.coulomb_friction_n = 0.0;
  const DcMotorParams& m = model.actuators.motor;
  const double b = DcMotorBackEmfDampingNspm(m) + model.actuators.viscous_friction_nspm;
  for (double duty : {1.0, -1.0, 0.6, 0.3, -0.3, 0.5 * m.dead_band_duty}) {
    Plant plant(model, test::OdeOptionsFor("arkode_erk"));
    plant.Reset(0.0, Config().plant_sim.initial_pose, Vector6d::Zero());
    plant.SetDutyCommand(Vector6d::Constant(duty));
    // 15 mechanical time constants m_r / b (~11 ms); the legs move < 5 mm.
    for (int k = 0; k < 150; ++k) plant.Advance(1e-3);
    const double expected = DcMotorDriveForce(m, duty) / b;
    const Vector6d speed = LegSpeed(plant);
    spdlog::info("duty {:+.3f}: leg speed {:.5f} m/s (expected {:.5f})", duty, speed.mean(),
                 expected);
    EXPECT_NEAR(speed.maxCoeff(), expected, 0.005 * std::abs(expected) + 1e-7) << duty;
    EXPECT_NEAR(speed.minCoeff(), expected, 0.005 * std::abs(expected) + 1e-7) << duty;
    EXPECT_FALSE(plant.InEndStop());
  }
  EXPECT_NEAR(DcMotorDriveForce(m, 1.0) / DcMotorBackEmfDampingNspm(m),
              m.no_load_speed_mps * (m.supply_voltage_v - m.bridge_drop_v) / m.rated_voltage_v,
              1e-12);
}

// Full duty into the upper stroke ends without gravity: at rest the end stop
// carries the stall force, F_stop = -F_full (its spring's deflection shows it).
TEST(DcMotorLeg, StallForceAtTheStrokeEnd) {
  PlantModel model = DcMotorModel();
  model.platform.gravity_mps2 = 0.0;
  model.actuators.endstop_stiffness_npm = 1e6;  // deflection ~0.1 mm: well resolved
  Plant plant(model, test::OdeOptionsFor("arkode_erk"));
  plant.Reset(0.0, Config().plant_sim.initial_pose, Vector6d::Zero());
  plant.SetDutyCommand(Vector6d::Constant(1.0));
  // To the ends at the no-load speed, then 1 s at rest there.
  const double l_max = model.actuators.min_length_m + model.actuators.stroke_m;
  const double travel_m =
      l_max - InverseKinematics(model.platform, Config().plant_sim.initial_pose).minCoeff();
  const double speed_mps = DcMotorForceAtFullDuty(model.actuators.motor) /
                           DcMotorBackEmfDampingNspm(model.actuators.motor);
  const int ticks = static_cast<int>(1e3 * (travel_m / speed_mps + 1.0));
  for (int k = 0; k < ticks; ++k) plant.Advance(1e-3);
  const Vector6d lengths = InverseKinematics(model.platform, plant.q());
  const Vector6d stop_n = EndStopForce(model.actuators, lengths, LegSpeed(plant));
  const double f_full = DcMotorForceAtFullDuty(model.actuators.motor);
  spdlog::info("end-stop forces {:.2f} to {:.2f} N (stall {:.2f} N)", stop_n.minCoeff(),
               stop_n.maxCoeff(), f_full);
  EXPECT_GT(plant.counters().endstop_hits, 0);
  EXPECT_LT(LegSpeed(plant).cwiseAbs().maxCoeff(), 1e-6);
  for (int i = 0; i < kNumLegs; ++i) EXPECT_NEAR(-stop_n(i), f_full, 0.01 * f_full) << i;
}

// The leg forces an external downward force F on the platform puts on the
// legs at rest at q (N, positive = compressing pushes back: the legs' static
// forces).
Vector6d StaticLegForces(const PlatformParams& platform, const Vector6d& q, double down_n) {
  Vector6d wrench = Vector6d::Zero();
  wrench(2) = -down_n;
  return InverseDynamics(EvaluateDynamics(platform, q, Vector6d::Zero()), Vector6d::Zero(),
                         GeneralisedForceOfWrench(q, wrench));
}

// Downward loads on the platform at rest at q (N): `hold_n` puts at most
// hold_fraction of the back-drive force on any leg, `slip_n` at least
// slip_fraction of it on every leg.
struct BackDriveLoads {
  double hold_n = 0.0;
  double slip_n = 0.0;
};
BackDriveLoads LoadsAroundTheBackDriveForce(const PlantModel& model, const Vector6d& q,
                                            double hold_fraction, double slip_fraction) {
  const double f_bd = model.actuators.motor.back_drive_force_n;
  const Vector6d weight_n = StaticLegForces(model.platform, q, 0.0);
  const Vector6d per_newton = StaticLegForces(model.platform, q, 1.0) - weight_n;
  EXPECT_TRUE((per_newton.array() > 0.0).all());
  return {((hold_fraction * f_bd - weight_n.array()) / per_newton.array()).minCoeff(),
          ((slip_fraction * f_bd - weight_n.array()) / per_newton.array()).maxCoeff()};
}

// Zero duty: the screws hold the platform under a load that puts at most 80 %
// of the back-drive force on any leg, and give way under one that puts at
// least 120 % on every leg.
TEST(DcMotorLeg, SelfLockingHoldsBelowTheBackDriveForceAndGivesWayAbove) {
  const PlantModel model = DcMotorModel();
  const double f_bd = model.actuators.motor.back_drive_force_n;
  const Vector6d q0 = Config().plant_sim.initial_pose;
  const BackDriveLoads loads = LoadsAroundTheBackDriveForce(model, q0, 0.8, 1.2);
  const double hold_load_n = loads.hold_n;
  const double slip_load_n = loads.slip_n;

  for (const double load_n : {hold_load_n, slip_load_n}) {
    Plant plant(model, test::OdeOptionsFor("arkode_erk"));
    plant.Reset(0.0, q0, Vector6d::Zero());
    plant.SetDutyCommand(Vector6d::Zero());
    for (int k = 0; k < 50; ++k) plant.Advance(1e-3);  // the screws take hold
    Vector6d wrench = Vector6d::Zero();
    wrench(2) = -load_n;
    plant.SetExternalWrench(wrench);
    const double z0 = plant.q()(2);
    for (int k = 0; k < 1000; ++k) plant.Advance(1e-3);
    const double sink_m = z0 - plant.q()(2);
    spdlog::info("load {:.1f} N: sank {:.2e} m in 1 s, {} lock engagements", load_n, sink_m,
                 plant.counters().self_lock_engagements);
    EXPECT_GE(plant.counters().self_lock_engagements, kNumLegs);
    if (load_n == hold_load_n) {
      EXPECT_LT(std::abs(sink_m), 2.0 * f_bd / model.actuators.motor.lock_stiffness_npm);
    } else {
      EXPECT_GT(sink_m, 1e-3);
    }
  }
}

// The resistance the catch reads, for a leg whose motor is not energised
// (zero duty, or the power off) and that no spring holds: back-EMF while
// powered, the screw's viscous friction, and its dry friction at the
// back-drive force plus the truth's extra, smoothed over 1 mm/s.
TEST(DcMotorLeg, UndrivenResistanceIsDampingAndDryFriction) {
  const PlantModel model = DcMotorModel();
  const DcMotorParams& m = model.actuators.motor;
  const Vector6d coulomb_error_n = (Vector6d() << 0.0, 0.1, 0.2, 0.3, 0.0, 0.25).finished();
  const Vector6d lengths = Vector6d::Constant(model.actuators.min_length_m + 0.1);
  const Vector6d speeds =
      (Vector6d() << -4e-3, -1e-3, -2e-4, 3e-5, 7e-4, 2.5e-3).finished();  // m/s
  for (const bool power_off : {false, true}) {
    const Vector6d resistance_n =
        DcMotorUndrivenResistanceN(model.actuators, coulomb_error_n, power_off, lengths, speeds);
    const double damping_nspm =
        (power_off ? 0.0 : DcMotorBackEmfDampingNspm(m)) + model.actuators.viscous_friction_nspm;
    for (int i = 0; i < kNumLegs; ++i) {
      const double speed = std::abs(speeds(i));
      const double expected_n = damping_nspm * speed + (m.back_drive_force_n + coulomb_error_n(i)) *
                                                           std::tanh(speed / 1e-3);
      EXPECT_GT(resistance_n(i), 0.0);
      EXPECT_NEAR(resistance_n(i), expected_n, 1e-12 * expected_n) << i << " " << power_off;
    }
  }
}

// A leg moving slowly with its drive off (inside the dead band, or the power
// off) under a load below its back-drive force comes to rest and stays: the
// screw's dry friction would stop it, so the simulator's smoothed friction
// must not let it creep on at the speed where the smoothed force meets the
// load. One above the back-drive force keeps sinking.
TEST(DcMotorLeg, SelfLockingStopsAMovingLegBelowTheBackDriveForce) {
  const PlantModel model = DcMotorModel();
  const double f_bd = model.actuators.motor.back_drive_force_n;
  const Vector6d q0 = Config().plant_sim.initial_pose;
  const BackDriveLoads loads = LoadsAroundTheBackDriveForce(model, q0, 0.6, 1.2);
  const double hold_load_n = loads.hold_n;
  const double slip_load_n = loads.slip_n;
  Vector6d sinking = Vector6d::Zero();
  sinking(2) = -0.003;  // m/s
  for (const bool power_off : {false, true}) {
    for (const double load_n : {hold_load_n, slip_load_n}) {
      Plant plant(model, test::OdeOptionsFor("arkode_erk"));
      plant.Reset(0.0, q0, sinking);
      plant.SetDutyCommand(Vector6d::Zero());
      plant.SetActuatorsOff(power_off);
      Vector6d wrench = Vector6d::Zero();
      wrench(2) = -load_n;
      plant.SetExternalWrench(wrench);
      for (int k = 0; k < 300; ++k) plant.Advance(1e-3);  // 0.3 s to come to rest
      const double z0 = plant.q()(2);
      for (int k = 0; k < 1000; ++k) plant.Advance(1e-3);
      const double sink_m = z0 - plant.q()(2);
      spdlog::info("power {}, load {:.1f} N: sank {:.2e} m in the second after 0.3 s, {} catches",
                   power_off ? "off" : "on, zero duty", load_n, sink_m,
                   plant.counters().self_lock_engagements);
      if (load_n == hold_load_n) {
        EXPECT_GE(plant.counters().self_lock_engagements, kNumLegs) << power_off;
        EXPECT_LT(std::abs(sink_m), 2.0 * f_bd / model.actuators.motor.lock_stiffness_npm)
            << power_off;
        EXPECT_LT(LegSpeed(plant).cwiseAbs().maxCoeff(), 1e-6) << power_off;
      } else {
        EXPECT_GT(sink_m, 1e-3) << power_off;
      }
    }
  }
}

// Energy: the mechanical energy (rotors included, through M) changes by the
// work of the leg forces, sum F_leg Ld, integrated along the motion
// (duties in and out of the dead band, dry friction, back-EMF; no end stop).
TEST(DcMotorPower, EnergyChangesByTheWorkOfTheLegForces) {
  const PlantModel model = DcMotorModel();
  Plant plant(model, test::OdeOptionsFor("arkode_erk"));
  const Vector6d q0 = Config().plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  const double dt = 1e-4;
  double work_j = 0.0;
  double power_before = 0.0;
  const double e0 = PlantMechanicalEnergy(model, plant.q(), plant.qd());
  double largest_term_j = 0.0;
  for (int k = 0; k < 10000; ++k) {  // 1 s
    if (k % 10 == 0) {
      Vector6d duty;
      for (int i = 0; i < kNumLegs; ++i) duty(i) = 0.5 * std::sin(2.0 * M_PI * 1.5 * k * dt + i);
      plant.SetDutyCommand(duty);
    }
    power_before = plant.EvaluateRates().leg_force_n.dot(LegSpeed(plant));
    plant.Advance(dt);
    // Trapezoid over the step, each end with the inputs of the step.
    const PlantRates& rates = plant.EvaluateRates();
    const double power_after = rates.leg_force_n.dot(LegSpeed(plant));
    work_j += 0.5 * dt * (power_before + power_after);
    largest_term_j = std::max(largest_term_j, std::abs(work_j));
  }
  ASSERT_FALSE(plant.InEndStop());
  const double e1 = PlantMechanicalEnergy(model, plant.q(), plant.qd());
  spdlog::info("energy change {:.6e} J, work {:.6e} J", e1 - e0, work_j);
  EXPECT_GT(std::abs(e1 - e0), 1e-3);  // the legs did move the platform
  EXPECT_NEAR(e1 - e0, work_j, 2e-3 * largest_term_j);
}

// plant_sim's integration against a fixed-step RK4 of the same right-hand
// side at 10 us, with the same duties (energised throughout: the hold
// decisions are the plant's, at tick boundaries, and are not taken here).
TEST(DcMotorAccuracy, MatchesFineRk4WithZeroOrderHold) {
  const PlantModel model = DcMotorModel();
  Plant plant(model, test::OdeOptionsFor("arkode_erk"));
  const Vector6d q0 = Config().plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  PlantStateVector x_ref = PlantStateVector::Zero();
  x_ref.segment<6>(0) = q0;
  PlantInputs u_ref;
  const double dt = 1e-3;
  const int substeps = 100;
  double max_err_q = 0.0, max_err_qd = 0.0, max_excursion = 0.0;
  for (int k = 0; k < 1000; ++k) {
    Vector6d duty;
    for (int i = 0; i < kNumLegs; ++i) {
      duty(i) = 0.4 + 0.3 * std::sin(2.0 * M_PI * 2.0 * k * dt + i);  // out of the dead band
      if (i % 2 == 1) duty(i) = -duty(i);
    }
    plant.SetDutyCommand(duty);
    u_ref.duty = duty;
    plant.Advance(dt);
    for (int s = 0; s < substeps; ++s) x_ref = test::Rk4Step(model, u_ref, x_ref, dt / substeps);
    max_err_q = std::max(max_err_q, (plant.q() - x_ref.segment<6>(0)).cwiseAbs().maxCoeff());
    max_err_qd = std::max(max_err_qd, (plant.qd() - x_ref.segment<6>(6)).cwiseAbs().maxCoeff());
    max_excursion = std::max(max_excursion, (plant.q() - q0).cwiseAbs().maxCoeff());
  }
  spdlog::info("DC motor: max |q err| {:.2e}, max |qd err| {:.2e}, excursion {:.4f}", max_err_q,
               max_err_qd, max_excursion);
  EXPECT_GT(max_excursion, 1e-3);
  EXPECT_EQ(plant.counters().endstop_hits, 0);
  EXPECT_EQ(plant.counters().self_lock_engagements, 0);
  EXPECT_LT(max_err_q, 1e-6);
  EXPECT_LT(max_err_qd, 1e-6);
}

// A force command to a DC-motor plant goes through its driver map, and
// SetDutyCommand is refused by an ideal force source.
TEST(DcMotorPlant, ForceCommandsGoThroughTheDriverMap) {
  const PlantModel model = DcMotorModel();
  Plant plant(model, test::OdeOptionsFor("arkode_erk"));
  plant.Reset(0.0, Config().plant_sim.initial_pose, Vector6d::Zero());
  const Vector6d force_n = (Vector6d() << 10.0, -20.0, 0.0, 50.0, 1e6, NAN).finished();
  plant.SetForceCommand(force_n);
  for (int i = 0; i < kNumLegs; ++i) {
    EXPECT_EQ(plant.inputs().duty(i), DutyForForce(model.duty_map, force_n(i))) << i;
  }
  EXPECT_EQ(plant.inputs().duty(2), 0.0);
  EXPECT_EQ(plant.inputs().duty(5), 0.0);  // NaN: no drive
  EXPECT_NEAR(DcMotorDriveForce(model.actuators.motor, plant.inputs().duty(4)),
              model.actuators.force_limit_n, 1e-9);  // clamped to the box
  Plant ideal(test::DefaultModel(), test::OdeOptionsFor("arkode_erk"));
  EXPECT_THROW(ideal.SetDutyCommand(Vector6d::Zero()), std::logic_error);
}

}  // namespace
}  // namespace stewart
