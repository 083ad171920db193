#include "stewart/identify/emulator_device.h"

#include <array>
#include <cmath>

#include "stewart/hw_emulator/sample_schedule.h"
#include "stewart/identify/inertial_fit.h"

namespace stewart::identify {
namespace {

// The host's clock runs at the device's plus this offset (us): another
// epoch, as on the prototype.
constexpr int64_t kHostEpochUs = 1'700'000'000'000'000;

std::unique_ptr<hw::PlantBackend> MakeBackend(const StackConfig& config, const PlantTruth& truth,
                                              bool noise) {
  if (truth.actuators.kind != ActuatorKind::kDcMotor) {
    throw IdentificationError(
        "the emulated legs are not DC motors: the truth (or the config without one) must say "
        "actuators.model: dc_motor");
  }
  hw::PlantBackendOptions o;
  o.noise = noise;
  return std::make_unique<hw::PlantBackend>(config, truth, o);
}

}  // namespace

EmulatorDevice::EmulatorDevice(const StackConfig& config, const PlantTruth& truth,
                               const hw::BringupOptions& bringup,
                               const EmulatorDeviceOptions& options)
    : backend_(MakeBackend(config, truth, options.noise)),
      device_(backend_.get()),
      bridge_(config.hw_bridge, config.platform.leg_min_length_m,
              config.platform.leg_max_length_m - config.platform.leg_min_length_m,
              config.actuators.force_limit_n, bringup),
      options_(options),
      period_us_(static_cast<uint64_t>(std::llround(1e6 / config.sensors.rate_hz))),
      device_us_(hw::SampleSchedule::kDeviceEpochUs) {}

void EmulatorDevice::SendFrame(uint64_t device_us) {
  std::array<uint8_t, hw::kMaxFrameSize> buffer{};
  const std::size_t size =
      bridge_.BuildCommandFrame(kHostEpochUs + static_cast<int64_t>(device_us), buffer.data());
  hw::DecodedFrame frame;
  if (hw::DecodeDatagram(buffer.data(), size, &frame) != hw::DecodeStatus::kOk) {
    device_.OnRxError();
    return;
  }
  device_.OnCommandFrame(frame.command, device_us);
}

ActuatorSample EmulatorDevice::NextSample() {
  for (;;) {
    device_us_ += period_us_;
    const hw::SensorFrame frame = device_.Tick(device_us_);
    hw::SensorSample sample;
    const int64_t host_rx_us =
        kHostEpochUs + static_cast<int64_t>(device_us_) + options_.sensor_delay_us;
    if (!bridge_.OnSensorFrame(frame, host_rx_us, &sample)) continue;
    // hw_bridge's node: the keep-alive (or a guard's zero) goes out at once.
    if (bridge_.TickFrameDue()) {
      SendFrame(device_us_ + static_cast<uint64_t>(2 * options_.sensor_delay_us));
    }
    ActuatorSample s;
    s.utime = sample.utime;
    s.leg_length_m = sample.leg_length_m;
    s.valid = (sample.status & hw::kStatusLegFault) == 0;
    const hw::AppliedDuty& applied = bridge_.applied();
    s.applied_duty = applied.duty;
    s.applied_since_utime = applied.since_utime;
    s.device_guard_mask = applied.guard_mask;
    return s;
  }
}

void EmulatorDevice::SetDuty(int64_t sample_utime, const Vector6d& duty) {
  const hw::CommandVerdict verdict = bridge_.OnDutyCommand(sample_utime, duty);
  if (verdict != hw::CommandVerdict::kAccepted) ++rejected_;
  if (!hw::SendsAtOnce(verdict)) return;
  SendFrame(device_us_ + static_cast<uint64_t>(options_.command_delay_us));
}

}  // namespace stewart::identify
