// The actuator identification in process (docs/hardware.md, "Identify the
// actuators"): the bring-up procedure against plant_sim's Plant and against
// the device emulator behind hw_bridge's library in bring-up mode, with
// DC-motor legs whose parameters differ from the config's by +20 % or -25 %;
// the fit and its overlay; the guard; and bad input.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/identify/actuator_fit.h"
#include "stewart/identify/actuator_overlay.h"
#include "stewart/identify/actuator_procedure.h"
#include "stewart/identify/emulator_device.h"
#include "stewart/identify/plant_device.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/kinematics.h"

namespace stewart::identify {
namespace {

// The stack: the shipped config with the P-16P overlay.
const StackConfig& Config() { return DcMotorStackConfig(); }

// The config's plant at home with other motors: each parameter the fit
// identifies, and the friction it cannot, +20 % or -25 % off the config's.
PlantTruth OtherMotors() {
  PlantTruth truth = TruthOfConfig(Config());
  truth.initial_pose = Config().home_pose;
  DcMotorParams& m = truth.actuators.motor;
  m.stall_force_n *= 1.2;
  m.no_load_speed_mps *= 0.75;
  m.reflected_mass_kg *= 1.2;
  m.dead_band_duty *= 1.2;
  m.coulomb_friction_n *= 0.75;
  truth.platform.leg.actuator_reflected_mass_kg = m.reflected_mass_kg;
  return truth;
}

ActuatorProcedureOptions ProcedureOptions() {
  const StackConfig& c = Config();
  ActuatorProcedureOptions o;
  o.guard = hw::DefaultBringupGuard(c.platform.leg_min_length_m, c.platform.leg_max_length_m,
                                    c.safety.leg_stroke.margin_m, c.actuators.motor);
  return o;
}

hw::BringupOptions Bringup() {
  hw::BringupOptions b;
  b.enabled = true;
  b.guard = ProcedureOptions().guard;
  return b;
}

// The fit as the tool runs it: F_c assumed as the config says, +- 100 %.
ActuatorFitOptions FitOptions() {
  ActuatorFitOptions o;
  o.coulomb_friction_n = Config().actuators.motor.coulomb_friction_n;
  o.coulomb_friction_sigma_n = o.coulomb_friction_n;
  return o;
}

// The truth's values in the fit's terms.
MotorVector TrueValues(const PlantTruth& truth) {
  const DcMotorParams& m = truth.actuators.motor;
  const double f_full = DcMotorForceAtFullDuty(m);
  MotorVector v;
  v(kDeadBandDuty) = m.dead_band_duty;
  v(kStallForceN) = m.stall_force_n;
  v(kNoLoadSpeedMps) = m.no_load_speed_mps;
  v(kReflectedMassKg) = m.reflected_mass_kg;
  v(kForceAtFullDutyN) = f_full;
  v(kLegDampingNspm) = DcMotorBackEmfDampingNspm(m) + truth.actuators.viscous_friction_nspm;
  v(kStartDuty) = m.dead_band_duty + (1.0 - m.dead_band_duty) * m.coulomb_friction_n / f_full;
  return v;
}

void Print(const ActuatorFit& fit, const MotorVector& truth) {
  for (int v = 0; v < kNumMotorValues; ++v) {
    std::printf("%-22s %10.5g +- %8.2g (fit %8.2g), true %10.5g: %+6.2f %% (%+.1f sigma)\n",
                kMotorValueNames[static_cast<std::size_t>(v)], fit.values(v), fit.sigma(v),
                fit.sigma_fit(v), truth(v), 100.0 * (fit.values(v) / truth(v) - 1.0),
                (fit.values(v) - truth(v)) / fit.sigma(v));
  }
}

// Every value the overlay writes within 5 %; the measured combinations (the
// leg damping, the force at full duty, the start duty) within 2 %; each
// within 3.5 of its stated sigma. The dead band rests on the assumed
// friction (not identifiable): its error is the friction's error times
// (1 - d0) / F_full, to within 3.5 sigma of the fit.
void ExpectRecovered(const ActuatorFit& fit, const PlantTruth& truth) {
  const MotorVector expected = TrueValues(truth);
  Print(fit, expected);
  for (int v = 0; v < kNumMotorValues; ++v) {
    const char* name = kMotorValueNames[static_cast<std::size_t>(v)];
    const double error = fit.values(v) / expected(v) - 1.0;
    EXPECT_LT(std::abs(error), 0.05) << name;
    EXPECT_LT(std::abs(fit.values(v) - expected(v)), 3.5 * fit.sigma(v)) << name;
  }
  for (const int v : {kLegDampingNspm, kForceAtFullDutyN, kStartDuty}) {
    EXPECT_LT(std::abs(fit.values(v) / expected(v) - 1.0), 0.02)
        << kMotorValueNames[static_cast<std::size_t>(v)];
  }
  const DcMotorParams& m = truth.actuators.motor;
  const double friction_bias = (m.coulomb_friction_n - FitOptions().coulomb_friction_n) *
                               (1.0 - m.dead_band_duty) / DcMotorForceAtFullDuty(m);
  EXPECT_NEAR(fit.values(kDeadBandDuty), m.dead_band_duty + friction_bias,
              3.5 * fit.sigma_fit(kDeadBandDuty));
  // The ramps' start duty lies near the line's (the simulated friction has
  // no static excess: a little below it, where the smoothed friction is not
  // yet at full strength).
  for (const LegFit& leg : fit.legs) {
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(leg.ramp_start_duty[i], leg.line_start_duty[i], 0.02) << "leg " << leg.leg;
    }
  }
}

TEST(ActuatorIdentification, RecoversOtherMotorsInSimulation) {
  const PlantTruth truth = OtherMotors();
  PlantDevice device(Config(), truth);
  const ActuatorRecord record = RunActuatorProcedure(&device, ProcedureOptions());
  EXPECT_EQ(record.legs.size(), 6u);
  const ActuatorFit fit = FitActuators(Config().platform, Config().actuators, record, FitOptions());
  ExpectRecovered(fit, truth);
  // Back where it started: every leg within 1 mm of its home length.
  const Vector6d home = InverseKinematics(Config().platform, truth.initial_pose);
  const Vector6d now = InverseKinematics(Config().platform, device.plant().q());
  EXPECT_LT((now - home).cwiseAbs().maxCoeff(), 1e-3);
}

// The hardware path without processes: the emulator (the device's 12-bit
// ADC, duty in drive counts, commands 0.3 ms after their sample) behind
// hw_bridge's bring-up mode, whose echo gives the fit the times. The pot is
// read by the device's ADC alone, as on the prototype: the sensor model's
// own 10-bit ADC in front of it (the emulator's default) puts two ADCs in
// series, whose uneven steps bias the rotor mass by +3..+7 % (docs/hardware.md,
// "Identify the actuators").
TEST(ActuatorIdentification, RecoversOtherMotorsThroughTheBridgeAndTheEmulator) {
  PlantTruth truth = OtherMotors();
  truth.sensors.leg_adc_bits = 0;
  EmulatorDevice device(Config(), truth, Bringup());
  const ActuatorRecord record = RunActuatorProcedure(&device, ProcedureOptions());
  EXPECT_EQ(device.rejected_commands(), 0);
  EXPECT_EQ(device.bridge().counters().guard_trips, 0u);
  const ActuatorFit fit = FitActuators(Config().platform, Config().actuators, record, FitOptions());
  ExpectRecovered(fit, truth);
}

// The overlay: only the four motor keys (plus nothing else here: the
// config's force limit is below the identified force at full duty), each
// with its uncertainty, and it applies on top of the P-16P overlay.
TEST(ActuatorIdentification, OverlayAppliesOnTopOfTheP16POverlay) {
  const PlantTruth truth = OtherMotors();
  PlantDevice device(Config(), truth);
  ActuatorProcedureOptions o = ProcedureOptions();
  o.legs = {0, 3};
  const ActuatorFit fit = FitActuators(Config().platform, Config().actuators,
                                       RunActuatorProcedure(&device, o), FitOptions());
  const std::string text = FormatActuatorOverlay(fit, Config().actuators, FitOptions(), "a test");
  const YAML::Node overlay = YAML::Load(text);
  ASSERT_TRUE(overlay.IsMap());
  EXPECT_EQ(overlay.size(), 1u);
  EXPECT_EQ(overlay["actuators"].size(), 1u);
  EXPECT_EQ(overlay["actuators"]["motor"].size(), 4u);
  EXPECT_NE(text.find("# a test"), std::string::npos);
  EXPECT_NE(text.find("reflected_mass_kg: "), std::string::npos);
  EXPECT_NE(text.find("+-"), std::string::npos);
  EXPECT_NE(text.find("not identifiable"), std::string::npos);

  const std::string path =
      ::testing::TempDir() + "actuator_overlay_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << text;
  const StackConfig identified = LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath(), path});
  const DcMotorParams& m = identified.actuators.motor;
  EXPECT_NEAR(m.stall_force_n, fit.values(kStallForceN), 1e-3 * fit.values(kStallForceN));
  EXPECT_NEAR(m.reflected_mass_kg, fit.values(kReflectedMassKg), 1e-3 * m.reflected_mass_kg);
  // hw_bridge's force -> duty map follows (config/src/hw_bridge_config.cc).
  EXPECT_NEAR(identified.hw_bridge.force_at_full_duty_n, DcMotorForceAtFullDuty(m), 1e-9);
  EXPECT_EQ(identified.hw_bridge.duty_deadband, m.dead_band_duty);
  EXPECT_EQ(m.coulomb_friction_n, Config().actuators.motor.coulomb_friction_n);  // not written

  // Weaker motors than the config's force limit: the overlay lowers it, or
  // the config would not load.
  ActuatorFit weak = fit;
  weak.values(kForceAtFullDutyN) = 0.8 * Config().actuators.force_limit_n;
  const YAML::Node lowered =
      YAML::Load(FormatActuatorOverlay(weak, Config().actuators, FitOptions(), "weak"));
  EXPECT_LE(lowered["actuators"]["force_limit_n"].as<double>(), weak.values(kForceAtFullDutyN));
  std::remove(path.c_str());
}

// The absolute force scale is the leg's load: without gravity the fit
// cannot tell it and says so.
TEST(ActuatorIdentification, ForceScaleNeedsTheLegsLoad) {
  StackConfig c = Config();
  c.platform.gravity_mps2 = 0.0;
  PlantTruth truth = OtherMotors();
  truth.platform.gravity_mps2 = 0.0;
  PlantDevice device(c, truth);
  ActuatorProcedureOptions o = ProcedureOptions();
  o.legs = {1};
  const ActuatorRecord record = RunActuatorProcedure(&device, o);
  try {
    FitActuators(c.platform, c.actuators, record, FitOptions());
    FAIL() << "fitted a force scale without a load";
  } catch (const IdentificationError& e) {
    EXPECT_NE(std::string(e.what()).find("force scale is not determined"), std::string::npos)
        << e.what();
  }
}

// ---- The guard ----

// Home, but leg 0 only 3 mm outside the guard's end zone at its retracted
// end: the first inward excursion runs into the zone.
PlantTruth Leg0NearItsRetractedEnd(double margin_m) {
  const StackConfig& c = Config();
  Vector6d lengths = InverseKinematics(c.platform, c.home_pose);
  lengths(0) = c.platform.leg_min_length_m + margin_m + 3e-3;
  const ForwardKinematicsResult fk = ForwardKinematics(c.platform, lengths, c.home_pose);
  EXPECT_TRUE(fk.converged);
  PlantTruth truth = OtherMotors();
  truth.initial_pose = fk.q;
  return truth;
}

double TrueLegLength(const Plant& plant, int leg) {
  return InverseKinematics(plant.model().platform, plant.q())(leg);
}

TEST(ActuatorGuard, StopsALegBeforeItsStrokeEnd) {
  const ActuatorProcedureOptions o = [] {
    ActuatorProcedureOptions p = ProcedureOptions();
    p.legs = {0};
    return p;
  }();
  const double l_min = Config().platform.leg_min_length_m;
  PlantDevice device(Config(), Leg0NearItsRetractedEnd(o.guard.margin_m));
  try {
    RunActuatorProcedure(&device, o);
    FAIL() << "the guard did not stop the run";
  } catch (const GuardTrip& trip) {
    std::printf("%s\n", trip.what());
    EXPECT_EQ(trip.leg, 0);
    EXPECT_EQ(trip.reason, hw::GuardReason::kRetractedEnd);
    EXPECT_NE(std::string(trip.what()).find("leg 0 retracted_end"), std::string::npos);
    EXPECT_GT(trip.length_m, l_min + o.guard.margin_m - 5e-4);
  }
  // Zero duty went out at once: the leg stops within a fraction of a mm
  // inside the zone, far from its stroke end, and stays.
  for (int k = 0; k < 200; ++k) device.NextSample();
  const double stopped_m = TrueLegLength(device.plant(), 0);
  std::printf("leg 0 stopped %.2f mm from its retracted end (zone %.1f mm)\n",
              1e3 * (stopped_m - l_min), 1e3 * o.guard.margin_m);
  EXPECT_GT(stopped_m, l_min + o.guard.margin_m - 5e-4);
  EXPECT_EQ(device.plant().inputs().duty, Vector6d::Zero());
  EXPECT_EQ(device.plant().counters().endstop_hits, 0);
}

// A motor three times as fast as the config's (a runaway, a wrong motor):
// the direction check's duty alone takes the leg past the cap.
TEST(ActuatorGuard, StopsALegFasterThanTheCap) {
  ActuatorProcedureOptions o = ProcedureOptions();
  o.legs = {4};
  o.guard.speed_cap_mps = 0.02;
  PlantTruth fast = OtherMotors();
  fast.actuators.motor.no_load_speed_mps *= 4.0;
  PlantDevice device(Config(), fast);
  try {
    RunActuatorProcedure(&device, o);
    FAIL() << "the guard did not stop the run";
  } catch (const GuardTrip& trip) {
    std::printf("%s\n", trip.what());
    EXPECT_EQ(trip.leg, 4);
    EXPECT_EQ(trip.reason, hw::GuardReason::kSpeed);
    EXPECT_GT(std::abs(trip.speed_mps), 0.02);
  }
  for (int k = 0; k < 50; ++k) device.NextSample();
  const Plant& plant = device.plant();
  const Vector6d leg_speed = LegLengthJacobian(plant.model().platform, plant.q()) * plant.qd();
  EXPECT_LT(leg_speed.cwiseAbs().maxCoeff(), 1e-4);
}

// hw_bridge's own guard (a tighter speed cap than the procedure's) zeroes
// the leg on the bridge's readings; the procedure sees it in the echo and
// stops too.
TEST(ActuatorGuard, TheBridgesGuardStopsTheRunToo) {
  hw::BringupOptions bringup = Bringup();
  bringup.guard.speed_cap_mps = 0.02;
  PlantTruth fast = OtherMotors();
  fast.actuators.motor.no_load_speed_mps *= 4.0;
  EmulatorDevice device(Config(), fast, bringup);
  ActuatorProcedureOptions o = ProcedureOptions();
  o.legs = {2};
  try {
    RunActuatorProcedure(&device, o);
    FAIL() << "the bridge's guard did not stop the run";
  } catch (const GuardTrip& trip) {
    EXPECT_EQ(trip.leg, 2);
    EXPECT_NE(std::string(trip.what()).find("hw_bridge --bringup"), std::string::npos);
  }
  // It tripped once, and the procedure's zero duty re-armed it.
  EXPECT_EQ(device.bridge().counters().guard_trips, 1u);
  EXPECT_EQ(device.bridge().guard().tripped_mask(), 0);
}

// ---- Bad input ----

// Between the procedure and a device: faults on demand, and the last duty
// the procedure set.
class FaultyDevice final : public ActuatorDevice {
 public:
  explicit FaultyDevice(ActuatorDevice* inner) : inner_(inner) {}

  ActuatorSample NextSample() override {
    ActuatorSample s = inner_->NextSample();
    ++samples_;
    if (nan_leg >= 0 && samples_ >= fault_at) s.leg_length_m(nan_leg) = NAN;
    if (frozen_leg >= 0) s.leg_length_m(frozen_leg) = 0.42;
    if (backwards && samples_ == fault_at) s.utime -= 5000;
    if (flagged && samples_ >= fault_at) s.valid = false;
    return s;
  }
  void SetDuty(int64_t sample_utime, const Vector6d& duty) override {
    last_duty = duty;
    ++duties;
    Vector6d applied = duty;
    if (reversed_leg >= 0) applied(reversed_leg) = -applied(reversed_leg);
    inner_->SetDuty(sample_utime, applied);
  }

  int nan_leg = -1;
  int frozen_leg = -1;
  int reversed_leg = -1;
  bool backwards = false;
  bool flagged = false;
  long fault_at = 1000;  // sample count at which the fault starts
  Vector6d last_duty = Vector6d::Constant(NAN);
  long duties = 0;

 private:
  ActuatorDevice* inner_;
  long samples_ = 0;
};

// Runs leg 1 on a faulty device; returns the error's message, and checks
// that zero duty was the last thing set.
std::string FailureOf(const std::function<void(FaultyDevice*)>& fault) {
  PlantDevice plant(Config(), OtherMotors());
  FaultyDevice device(&plant);
  fault(&device);
  ActuatorProcedureOptions o = ProcedureOptions();
  o.legs = {1};
  o.move_timeout_s = 1.0;
  try {
    RunActuatorProcedure(&device, o);
  } catch (const IdentificationError& e) {
    EXPECT_GT(device.duties, 0);
    EXPECT_EQ(device.last_duty, Vector6d::Zero()) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return "";
}

TEST(ActuatorBadInput, NonFiniteReading) {
  const std::string what = FailureOf([](FaultyDevice* d) { d->nan_leg = 3; });
  EXPECT_NE(what.find("non-finite reading of leg 3"), std::string::npos) << what;
}

TEST(ActuatorBadInput, ALegThatDoesNotMove) {
  const std::string what = FailureOf([](FaultyDevice* d) { d->frozen_leg = 1; });
  EXPECT_NE(what.find("leg 1: the direction check did not finish"), std::string::npos) << what;
  EXPECT_NE(what.find("does not move"), std::string::npos) << what;
}

TEST(ActuatorBadInput, AReversedMotor) {
  const std::string what = FailureOf([](FaultyDevice* d) { d->reversed_leg = 1; });
  EXPECT_NE(what.find("drive_sign[1] = -1"), std::string::npos) << what;
}

TEST(ActuatorBadInput, TimeGoingBackwardsAndFlaggedSamples) {
  std::string what = FailureOf([](FaultyDevice* d) { d->backwards = true; });
  EXPECT_NE(what.find("went backwards"), std::string::npos) << what;
  what = FailureOf([](FaultyDevice* d) { d->flagged = true; });
  EXPECT_NE(what.find("flags the sample"), std::string::npos) << what;
}

TEST(ActuatorBadInput, OptionsAndRecordsTheFitCannotUse) {
  ActuatorProcedureOptions o = ProcedureOptions();
  o.legs = {0, 7};
  EXPECT_THROW(ValidateProcedureOptions(o), IdentificationError);
  o.legs = {2, 2};
  EXPECT_THROW(ValidateProcedureOptions(o), IdentificationError);
  o = ProcedureOptions();
  o.levels = {{0.3, 0.5}};
  EXPECT_THROW(ValidateProcedureOptions(o), IdentificationError);
  o = ProcedureOptions();
  o.excursion_m = 0.2;
  EXPECT_THROW(ValidateProcedureOptions(o), IdentificationError);

  EXPECT_THROW(FitActuators(Config().platform, Config().actuators, ActuatorRecord{}, FitOptions()),
               IdentificationError);
  ActuatorRecord rests_only;
  rests_only.legs.resize(1);
  LegTestRecord& leg = rests_only.legs[0];
  for (int k = 0; k < 100; ++k) {
    ActuatorSample s;
    s.utime = 1000 * k;
    s.leg_length_m = InverseKinematics(Config().platform, Config().home_pose);
    leg.samples.push_back(s);
  }
  EXPECT_THROW(FitActuators(Config().platform, Config().actuators, rests_only, FitOptions()),
               IdentificationError);

  // An ideal force source is not a DC motor.
  EXPECT_THROW(PlantDevice(DefaultStackConfig(), TruthOfConfig(DefaultStackConfig())),
               IdentificationError);
}

}  // namespace
}  // namespace stewart::identify
