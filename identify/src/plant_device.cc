#include "stewart/identify/plant_device.h"

#include <cmath>

#include "stewart/identify/inertial_fit.h"

namespace stewart::identify {
namespace {

SensorConfig Quiet(SensorConfig sensors, bool noise) {
  if (!noise) sensors.leg_pot_noise_std_m = 0.0;
  return sensors;
}

PlantModel DcMotorPlantOf(const PlantTruth& truth, const StackConfig& config) {
  if (truth.actuators.kind != ActuatorKind::kDcMotor) {
    throw IdentificationError(
        "the simulated legs are not DC motors: the truth (or the config without one) must say "
        "actuators.model: dc_motor");
  }
  PlantModel model = PlantModelOf(truth, config);
  // The device applies the duty itself: the plant's own delay queue is not
  // used (this device keeps the truth's latency and reports it).
  model.command_delay_s = 0.0;
  return model;
}

}  // namespace

PlantDevice::PlantDevice(const StackConfig& config, const PlantTruth& truth,
                         const PlantDeviceOptions& options)
    : plant_(DcMotorPlantOf(truth, config), OdeOptionsFrom(config.plant_sim)),
      sensors_(Quiet(truth.sensors, options.noise), truth.actuators, truth.platform.gravity_mps2,
               truth.sensor_errors),
      period_us_(static_cast<int64_t>(std::llround(1e6 / config.sensors.rate_hz))),
      delay_us_(static_cast<int64_t>(std::llround(truth.latency.total_s() * 1e6))) {
  plant_.Reset(0.0, truth.initial_pose, truth.initial_velocity);
  plant_.SetActuatorsOff(true);
  if (options.power_on_settle_s > 0.0) plant_.Advance(options.power_on_settle_s);
  utime_ = static_cast<int64_t>(std::llround(plant_.time_s() * 1e6));
}

ActuatorSample PlantDevice::NextSample() {
  // Run to the next sample instant, switching to each pending duty at its time.
  const int64_t next = utime_ + period_us_;
  while (pending_count_ > 0 &&
         pending_[static_cast<std::size_t>(pending_head_)].apply_utime <= next) {
    const Pending& p = pending_[static_cast<std::size_t>(pending_head_)];
    const int64_t at = std::max(p.apply_utime, utime_);
    if (at > utime_) {
      plant_.Advance(static_cast<double>(at - utime_) * 1e-6);
      utime_ = at;
    }
    if (!powered_) {
      plant_.SetActuatorsOff(false);
      powered_ = true;
    }
    plant_.SetDutyCommand(p.duty);
    if (p.duty != applied_) {
      applied_ = p.duty;
      applied_since_ = at;
    }
    pending_head_ = (pending_head_ + 1) % static_cast<int>(pending_.size());
    --pending_count_;
  }
  if (next > utime_) plant_.Advance(static_cast<double>(next - utime_) * 1e-6);
  utime_ = next;
  const PlantRates& rates = plant_.EvaluateRates();
  const SensorReading r =
      sensors_.Sample(plant_.q(), plant_.qd(), rates.x_dot.segment<6>(6), rates.terms.leg_length_m);
  ActuatorSample s;
  s.utime = utime_;
  s.leg_length_m = r.leg_length_m;
  s.applied_duty = applied_;
  s.applied_since_utime = applied_since_;
  return s;
}

void PlantDevice::SetDuty(int64_t sample_utime, const Vector6d& duty) {
  ++duty_commands_;
  if (pending_count_ == static_cast<int>(pending_.size())) {
    throw IdentificationError("simulated device: more than 64 duty commands in flight");
  }
  Vector6d d = duty.unaryExpr([](double v) { return std::isfinite(v) ? v : 0.0; });
  d = d.cwiseMax(-1.0).cwiseMin(1.0);
  const int tail = (pending_head_ + pending_count_) % static_cast<int>(pending_.size());
  // It acts from now (the sample it answers was taken at utime_) plus the
  // truth's latency.
  pending_[static_cast<std::size_t>(tail)] = Pending{std::max(sample_utime, utime_) + delay_us_, d};
  ++pending_count_;
}

}  // namespace stewart::identify
