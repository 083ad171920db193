#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "stewart/config/truth_loader.h"
#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_bridge/drive_map.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "stewart/hw_emulator/plant_backend.h"
#include "stewart/hw_emulator/sample_schedule.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"
#include "test_config.h"

namespace stewart::hw {
namespace {

class RecordingBackend : public DeviceBackend {
 public:
  struct Segment {
    DriveArray drive{};
    double dt_s = 0.0;
  };
  void Step(const DriveArray& drive, double dt_s) override {
    last = drive;
    segments.push_back({drive, dt_s});
  }
  RawReadings Sample() override { return {}; }
  DriveArray last{};
  std::vector<Segment> segments;
};

constexpr uint32_t kLinkSession = 0x5E55;  // the bridge's link session in these tests

CommandFrame Command(uint32_t seq, int16_t drive, uint32_t watchdog_us = 50000) {
  CommandFrame c;
  c.seq = seq;
  c.watchdog_us = watchdog_us;
  c.drive.fill(drive);
  c.session = kLinkSession;
  return c;
}

TEST(DeviceWatchdog, ZeroDriveWhenCommandsStop) {
  RecordingBackend backend;
  DeviceEmulator device(&backend);
  SensorFrame f = device.Tick(1000);
  EXPECT_NE(f.status & kStatusActuatorsOff, 0);  // no command yet
  // The session starts at rest (zero drive), then drives.
  EXPECT_EQ(device.OnCommandFrame(Command(1, 0, 20000), 1000), CommandAcceptance::kAdopted);
  EXPECT_EQ(device.OnCommandFrame(Command(2, 5000, 20000), 1000), CommandAcceptance::kApplied);
  f = device.Tick(2000);
  EXPECT_EQ(backend.last[0], 5000);
  EXPECT_EQ(f.status, 0);
  EXPECT_EQ(f.last_command_seq, 2U);
  EXPECT_EQ(f.command_session, kLinkSession);
  EXPECT_EQ(f.command_age_us, 1000U);
  f = device.Tick(21000);  // exactly the watchdog period: still in force
  EXPECT_EQ(backend.last[0], 5000);
  f = device.Tick(21001);
  EXPECT_EQ(backend.last[0], 0);
  EXPECT_NE(f.status & kStatusWatchdog, 0);
  EXPECT_EQ(f.applied_drive[0], 0);
  device.OnCommandFrame(Command(3, 7000, 20000), 22000);  // commands resume
  f = device.Tick(23000);
  EXPECT_EQ(backend.last[0], 7000);
  EXPECT_EQ(f.status & kStatusWatchdog, 0);
}

TEST(DeviceWatchdog, EnableBitOffAndSeqBookkeeping) {
  RecordingBackend backend;
  DeviceEmulator device(&backend);
  CommandFrame c = Command(10, 3000);
  c.flags = 0;
  device.OnCommandFrame(c, 0);
  SensorFrame f = device.Tick(1000);
  EXPECT_EQ(backend.last[0], 0);
  EXPECT_NE(f.status & kStatusActuatorsOff, 0);
  device.OnCommandFrame(Command(14, 3000), 1000);   // 11..13 lost
  device.OnCommandFrame(Command(12, -3000), 1100);  // reordered: ignored
  device.OnRxError();
  f = device.Tick(2000);
  EXPECT_EQ(backend.last[0], 3000);
  EXPECT_EQ(f.rx_lost, 3U);
  EXPECT_EQ(f.rx_corrupt, 1U);
}

TEST(DeviceWatchdog, CommandActsFromItsArrivalAndExpiresOnTime) {
  // The physics is split at every event: a command drives the legs from the
  // instant it arrives, and the watchdog cuts it at exactly rx + watchdog_us.
  RecordingBackend backend;
  DeviceEmulator device(&backend);
  device.Tick(1000);
  device.OnCommandFrame(Command(1, 0, 2500), 1300);  // the session's start, at rest
  device.OnCommandFrame(Command(2, 4000, 2500), 1300);
  device.Tick(2000);
  device.OnCommandFrame(Command(3, 6000, 2500), 2250);
  device.Tick(3000);
  device.Tick(5000);
  const SensorFrame f = device.Tick(6000);
  ASSERT_EQ(backend.segments.size(), 7U);
  const auto expect = [&](std::size_t i, int16_t drive, double dt_s) {
    EXPECT_EQ(backend.segments[i].drive[0], drive) << "segment " << i;
    EXPECT_NEAR(backend.segments[i].dt_s, dt_s, 1e-12) << "segment " << i;
  };
  expect(0, 0, 300e-6);      // 1000 .. 1300: nothing yet
  expect(1, 4000, 700e-6);   // 1300 .. 2000
  expect(2, 4000, 250e-6);   // 2000 .. 2250
  expect(3, 6000, 750e-6);   // 2250 .. 3000
  expect(4, 6000, 1750e-6);  // 3000 .. 4750: the watchdog expires at 2250 + 2500
  expect(5, 0, 250e-6);      // 4750 .. 5000
  expect(6, 0, 1000e-6);     // 5000 .. 6000
  EXPECT_NE(f.status & kStatusWatchdog, 0);
  EXPECT_EQ(f.device_time_us, 6000U);
}

// The config's plant at rest at home.
PlantTruth TruthAtRest(const StackConfig& c) {
  PlantTruth truth = TruthOfConfig(c);
  truth.initial_pose = c.home_pose;
  truth.initial_velocity.setZero();
  return truth;
}

std::unique_ptr<PlantBackend> MakeBackend(bool noise) {
  const StackConfig& c = test::Config();
  PlantBackendOptions o;
  o.noise = noise;
  return std::make_unique<PlantBackend>(c, TruthAtRest(c), o);
}

TEST(SampleSchedule, SamplesOnThePeriodGridAndDropsEveryNth) {
  SampleSchedule schedule(1000, 3);
  const uint64_t t0 = SampleSchedule::kDeviceEpochUs;
  EXPECT_FALSE(schedule.Due(t0 + 999));
  EXPECT_TRUE(schedule.Due(t0 + 1000));
  std::vector<bool> sent;
  for (int k = 1; k <= 6; ++k) {
    const SampleSchedule::Sample s = schedule.Take(t0 + 1000 * k + 400);  // late, but on the grid
    EXPECT_EQ(s.time_us, t0 + 1000 * static_cast<uint64_t>(k));
    sent.push_back(s.send);
  }
  EXPECT_EQ(sent, (std::vector<bool>{true, true, false, true, true, false}));
  EXPECT_EQ(schedule.ticks(), 6U);
  EXPECT_EQ(schedule.skipped(), 0U);
}

TEST(SampleSchedule, SkipsTheBacklogAfterBeingDescheduled) {
  SampleSchedule schedule(1000, 0);
  const uint64_t t0 = SampleSchedule::kDeviceEpochUs;
  // Ten periods behind: still caught up sample by sample, not a stall.
  EXPECT_FALSE(schedule.Stalled(t0 + 11'000));
  EXPECT_EQ(schedule.Take(t0 + 11'000).time_us, t0 + 1000);
  EXPECT_EQ(schedule.skipped(), 0U);
  // Far behind: a stall (the node drops the commands queued meanwhile), one
  // sample at the newest grid point, the rest skipped.
  EXPECT_TRUE(schedule.Stalled(t0 + 50'500));
  const SampleSchedule::Sample s = schedule.Take(t0 + 50'500);
  EXPECT_EQ(s.time_us, t0 + 50'000);
  EXPECT_TRUE(s.send);
  EXPECT_EQ(schedule.skipped(), 48U);
  EXPECT_EQ(schedule.next_tick_us(), t0 + 51'000);
}

TEST(PlantBackend, UnpoweredLegsHoldThePose) {
  // Zero drive: the P-16P lead screws hold every leg (plant_sim's power-off
  // lock), so the platform stays put under its weight.
  std::unique_ptr<PlantBackend> backend = MakeBackend(false);
  const ImuScale imu(test::Config().hw_bridge);
  const double g = test::Config().platform.gravity_mps2;
  // From the first sample at power-on the locks carry the weight: +g, not free fall.
  EXPECT_NEAR(imu.AccelMps2(backend->Sample().accel_raw).z(), g, 0.01);
  EXPECT_LT((backend->q() - test::Config().home_pose).norm(), 1e-4);  // the sag
  const Vector6d q0 = backend->q();
  for (int k = 0; k < 200; ++k) backend->Step(DriveArray{}, 1e-3);
  EXPECT_TRUE(backend->actuators_off());
  EXPECT_LT((backend->q() - q0).head<3>().norm(), 1e-4);
  const RawReadings raw = backend->Sample();
  EXPECT_NEAR(imu.AccelMps2(raw.accel_raw).z(), g, 0.01);
  EXPECT_EQ(raw.status, 0);
}

TEST(PlantBackend, GravityCompensationThroughTheBridgeMapHoldsStill) {
  // The bridge's map forward, the emulator's inverse: the gravity-compensating
  // forces keep the platform nearly still (only drive quantisation remains).
  const StackConfig& c = test::Config();
  std::unique_ptr<PlantBackend> backend = MakeBackend(false);
  const DriveMap map(c.hw_bridge, c.actuators.force_limit_n);
  const DynamicsTerms terms = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  const Vector6d f_hold = InverseDynamics(terms, Vector6d::Zero());
  const DriveArray drive = map.ForceToDrive(f_hold).drive;
  for (int k = 0; k < 500; ++k) backend->Step(drive, 1e-3);
  EXPECT_FALSE(backend->actuators_off());
  EXPECT_LT((backend->force_cmd_n() - f_hold).cwiseAbs().maxCoeff(), 2e-3);
  EXPECT_LT((backend->q() - c.home_pose).head<3>().norm(), 1e-3);
  EXPECT_LT(backend->qd().norm(), 1e-2);
  // ...and extra force on every leg raises it.
  DriveArray up = map.ForceToDrive(f_hold + Vector6d::Constant(5.0)).drive;
  for (int k = 0; k < 200; ++k) backend->Step(up, 1e-3);
  EXPECT_GT(backend->q()(2), c.home_pose(2) + 1e-3);
}

TEST(PlantBackend, SamplesDecodeBackToTheTrueLegLengths) {
  const StackConfig& c = test::Config();
  std::unique_ptr<PlantBackend> backend = MakeBackend(true);
  const LegCalibration cal(c.hw_bridge, c.platform.leg_min_length_m,
                           c.platform.leg_max_length_m - c.platform.leg_min_length_m);
  const Vector6d truth = InverseKinematics(c.platform, backend->q());
  const RawReadings raw = backend->Sample();
  const double count_m = (c.platform.leg_max_length_m - c.platform.leg_min_length_m) /
                         (c.hw_bridge.adc_extended(0) - c.hw_bridge.adc_retracted(0));
  // The simulator's ADC step, then the device's count, then the pot noise.
  const double tolerance_m = 0.5 * LegAdcResolution(c.sensors, c.actuators) + 0.5 * count_m +
                             5 * c.sensors.leg_pot_noise_std_m;
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(cal.LengthM(i, raw.adc[static_cast<std::size_t>(i)]), truth(i), tolerance_m);
  }
}

// The acceptance of the emulator: bridge + emulator, without transports, in
// a closed loop, against plant_sim's Plant and SensorModel driven with the
// same forces (as plant_sim in lockstep: the force answering sample k acts
// from t_k). Both sides must agree up to the drive and ADC quantisation.
// The leg-space PD both sides run on their own ground truth: gains (N/m,
// N s/m) and the amplitude (m) of the 0.5 Hz leg motion it tracks.
struct SwapControl {
  double kp_npm;
  double kd_nspm;
  double amplitude_m;
  /// Accelerometer samples allowed beyond the rounding bound (and then
  /// within 3 noise std instead of 1).
  int accel_outliers_allowed = 0;
};

// Device emulator behind hw_bridge's maps vs plant_sim's library driven
// directly, with the same control law on each side's ground truth.
void ExpectBridgePlusEmulatorEqualsPlantSim(const StackConfig& c, const SwapControl& gains) {
  constexpr int kTicks = 3000;  // 3 s at 1 kHz
  constexpr int64_t kPeriodUs = 1000;
  constexpr uint64_t kDeviceEpochUs = 7'000'000;
  constexpr int64_t kHostEpochUs = 1'700'000'000'000'000;
  constexpr int64_t kLinkDelayUs = 40;

  // Device + bridge.
  PlantBackend backend(c, TruthAtRest(c));
  DeviceEmulator device(&backend);
  HwBridge bridge(c.hw_bridge, c.platform.leg_min_length_m,
                  c.platform.leg_max_length_m - c.platform.leg_min_length_m,
                  c.actuators.force_limit_n, {}, c.guard);
  constexpr int64_t kSafetySession = 5;  // the safety session the commands come from
  // plant_sim's library, as its node uses it (legs locked until the first command).
  OdeOptions ode;
  ode.rel_tol = c.plant_sim.rel_tol;
  ode.abs_tol = c.plant_sim.abs_tol;
  Plant plant(PlantModelOf(TruthOfConfig(c), c), ode);
  plant.Reset(0.0, c.home_pose, Vector6d::Zero());
  plant.SetActuatorsOff(true);
  plant.Advance(PlantBackendOptions{}.power_on_settle_s);  // as the device at power-on
  // The pots unquantised, as the emulator's plant reads them: there the
  // device's ADC is the only quantiser.
  SensorConfig unquantised = c.sensors;
  unquantised.leg_adc_bits = 0;
  SensorModel sensors(unquantised, c.actuators, c.platform.gravity_mps2);

  const DynamicsTerms home = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  const Vector6d f_hold = InverseDynamics(home, Vector6d::Zero());
  const Vector6d l_home = home.leg_length_m;
  // A leg-space PD on each side's own ground truth, tracking 4 mm of leg
  // motion at 0.5 Hz: forces stay well outside the bridge's dead zone.
  const auto control = [&](const Vector6d& q, const Vector6d& qd, double t_s) {
    const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
    const Vector6d l_ref = l_home + Vector6d::LinSpaced(-1.0, 1.0) * gains.amplitude_m *
                                        std::sin(2.0 * M_PI * 0.5 * t_s);
    return Vector6d(f_hold + gains.kp_npm * (l_ref - terms.leg_length_m) -
                    gains.kd_nspm * (terms.H.transpose() * qd));
  };

  const double count_m =
      c.actuators.stroke_m / (c.hw_bridge.adc_extended(0) - c.hw_bridge.adc_retracted(0));
  double max_dq = 0.0, max_dqd = 0.0, max_drate = 0.0, max_dgyro = 0.0, max_daccel = 0.0,
         min_force = 1e9;
  long legs_within_a_count = 0, legs_total = 0;
  double max_dleg = 0.0, max_travel = 0.0;
  int accel_outliers = 0;
  int64_t last_utime = 0;
  for (int k = 0; k < kTicks; ++k) {
    const double t_s = k * kPeriodUs * 1e-6;
    const uint64_t device_us = kDeviceEpochUs + static_cast<uint64_t>(k * kPeriodUs);
    // Sample k on both sides.
    const SensorFrame frame = device.Tick(device_us);
    SensorSample sample;
    ASSERT_TRUE(bridge.OnSensorFrame(
        frame, kHostEpochUs + static_cast<int64_t>(device_us) + kLinkDelayUs, &sample));
    if (k > 0) {
      ASSERT_EQ(sample.utime - last_utime, kPeriodUs);
    }
    last_utime = sample.utime;
    const PlantRates& rates = plant.EvaluateRates();
    const SensorReading reading =
        sensors.Sample(plant.q(), plant.qd(), rates.x_dot.segment<6>(6), rates.terms.leg_length_m);
    max_dq = std::max(max_dq, (backend.q() - plant.q()).cwiseAbs().maxCoeff());
    max_travel = std::max(max_travel, (rates.terms.leg_length_m - l_home).cwiseAbs().maxCoeff());
    const Vector6d dqd = backend.qd() - plant.qd();
    max_dqd = std::max(max_dqd, dqd.head<3>().cwiseAbs().maxCoeff());
    max_drate = std::max(max_drate, dqd.tail<3>().cwiseAbs().maxCoeff());
    for (int i = 0; i < 6; ++i) {
      const double d = std::abs(sample.leg_length_m(i) - reading.leg_length_m(i));
      max_dleg = std::max(max_dleg, d);
      legs_within_a_count += d <= count_m ? 1 : 0;
      ++legs_total;
    }
    max_dgyro = std::max(max_dgyro, (sample.gyro_radps - reading.gyro_radps).cwiseAbs().maxCoeff());
    const double daccel = (sample.accel_mps2 - reading.accel_mps2).cwiseAbs().maxCoeff();
    max_daccel = std::max(max_daccel, daccel);
    if (daccel > 0.5 * c.hw_bridge.accel_mps2_per_lsb + 0.01) ++accel_outliers;

    // The force answering sample k, on both sides from t_k.
    const Vector6d f_emu = control(backend.q(), backend.qd(), t_s);
    const Vector6d f_sim = control(plant.q(), plant.qd(), t_s);
    min_force = std::min(min_force, f_emu.cwiseAbs().minCoeff());
    if (k == 0) {
      ASSERT_EQ(bridge.OnAnnouncement({sample.utime, 1, kSafetySession}, true, 0),
                AnnouncementVerdict::kAdopted);
    }
    ForceCommand command_emu;
    command_emu.utime = command_emu.sample_utime = sample.utime;
    command_emu.seq = k;
    command_emu.force_n = f_emu;
    command_emu.session_id = kSafetySession;
    ASSERT_EQ(bridge.OnSafeCommand(command_emu, true), CommandVerdict::kAccepted);
    std::array<uint8_t, kMaxFrameSize> buffer{};
    const std::size_t size = bridge.BuildCommandFrame(sample.utime, buffer.data());
    DecodedFrame command;
    ASSERT_EQ(DecodeDatagram(buffer.data(), size, &command), DecodeStatus::kOk);
    const CommandAcceptance accepted = device.OnCommandFrame(command.command, device_us);
    if (k == 0) {
      // The link session's handshake: the bridge sends zero drive until the
      // device echoes its session (from sample 1 on), so both plants hold
      // their legs over this first period.
      ASSERT_EQ(bridge.last_reason(), DriveReason::kSessionPending);
      ASSERT_EQ(accepted, CommandAcceptance::kAdopted);
    } else {
      ASSERT_EQ(bridge.last_reason(), DriveReason::kCommand);
      ASSERT_EQ(accepted, CommandAcceptance::kApplied);
      plant.SetActuatorsOff(false);
      plant.SetForceCommand(f_sim);
    }
    plant.Advance(kPeriodUs * 1e-6);
  }
  std::printf(
      "[bridge+emulator vs plant_sim] 3 s: max |dq| %.2e, max |dqd| %.2e m/s %.2e rad/s, legs "
      "within a count "
      "%.4f (max %.2e m), max |dgyro| %.2e rad/s, max |daccel| %.2e m/s^2, min |F| %.2f N\n",
      max_dq, max_dqd, max_drate, static_cast<double>(legs_within_a_count) / legs_total, max_dleg,
      max_dgyro, max_daccel, min_force);
  EXPECT_GT(min_force, c.hw_bridge.force_deadzone_n);  // the comparison stays outside the dead zone
  // Drive quantisation (1 count = 3.3 mN) against the PD's 300 N/m: microns;
  // on the light rotations (4e-3 kg m^2) a few 1e-4 rad/s.
  EXPECT_LT(max_dq, 2e-5);
  EXPECT_LT(max_dqd, 1e-4);
  EXPECT_LT(max_drate, 5e-4);
  // Same seed, same draws: the readings differ by the device's count and
  // LSB roundings only (and the microns of trajectory difference).
  EXPECT_GT(static_cast<double>(legs_within_a_count) / legs_total, 0.99);
  EXPECT_LE(max_dleg, count_m);
  // Half an LSB plus the rate difference above; both far below the noise.
  EXPECT_LE(max_dgyro, 0.5 * c.hw_bridge.gyro_radps_per_lsb + 5e-4);
  EXPECT_LT(max_dgyro, c.sensors.gyro_noise_std_radps);
  EXPECT_LE(accel_outliers, gains.accel_outliers_allowed);
  EXPECT_LT(max_daccel, gains.accel_outliers_allowed > 0 ? 3.0 * c.sensors.accel_noise_std_mps2
                                                         : c.sensors.accel_noise_std_mps2);
  EXPECT_GT(max_travel, 0.5 * gains.amplitude_m);  // the legs did follow
}

TEST(PlantBackend, BridgePlusEmulatorEqualsPlantSim) {
  // 4 mm of leg motion: forces stay well outside the bridge's dead zone.
  ExpectBridgePlusEmulatorEqualsPlantSim(test::Config(), SwapControl{300.0, 30.0, 4e-3});
}

// The same with the P-16P legs: the emulator drives its motors with the duty
// it receives, plant_sim turns the force into a duty by the same map
// (unquantised). The motors' back-EMF damps the legs, so the PD is stiff and
// has no damping of its own; 1 mm at 0.5 Hz keeps the duty below 0.4. Where
// a leg reverses, the emulator's duty, rounded to a count, can sit on the
// dead band's edge for one sample while plant_sim's is just outside it: that
// motor is off for 1 ms and the screw's friction jolts the accelerometer
// (2 samples of 3000 here).
TEST(PlantBackend, BridgePlusEmulatorEqualsPlantSimWithDcMotorLegs) {
  const StackConfig c = test::DcMotorConfig();
  ExpectBridgePlusEmulatorEqualsPlantSim(c, SwapControl{3e4, 0.0, 1e-3, 6});
}

}  // namespace
}  // namespace stewart::hw

namespace stewart::hw {
namespace {

// The emulator's plant takes its physics from a truth: under the drive that
// holds the model's platform, a platform 50 % heavier (friction off) sinks
// by 1/2 a t^2 more, a from the truth's dynamics.
TEST(PlantBackend, HeavierTruthSinksAtTheExpectedRate) {
  const StackConfig& c = test::Config();
  PlantTruth exact = TruthAtRest(c);
  exact.actuators.viscous_friction_nspm = 0.0;
  PlantTruth heavy = exact;
  heavy.platform.platform_mass_kg *= 1.5;
  PlantBackendOptions o;
  o.noise = false;
  o.power_on_settle_s = 0.0;
  PlantBackend exact_backend(c, exact, o), heavy_backend(c, heavy, o);
  const DriveMap drive_map(c.hw_bridge, c.actuators.force_limit_n);
  const Vector6d hold_n = InverseDynamics(
      EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero()), Vector6d::Zero());
  const DriveArray drive = drive_map.ForceToDrive(hold_n).drive;
  const Vector6d applied_n = drive_map.DriveToForce(drive);
  constexpr double kT = 0.05;
  constexpr int kSteps = 50;
  for (int k = 0; k < kSteps; ++k) {
    exact_backend.Step(drive, kT / kSteps);
    heavy_backend.Step(drive, kT / kSteps);
  }
  auto qdd_z = [&](const PlatformParams& p) {
    return ForwardDynamics(EvaluateDynamics(p, c.home_pose, Vector6d::Zero()), applied_n)(2);
  };
  const double expected = 0.5 * (qdd_z(heavy.platform) - qdd_z(exact.platform)) * kT * kT;
  ASSERT_LT(expected, -1e-3);
  EXPECT_NEAR(heavy_backend.q()(2) - exact_backend.q()(2), expected, 0.03 * std::abs(expected));
}

}  // namespace
}  // namespace stewart::hw
