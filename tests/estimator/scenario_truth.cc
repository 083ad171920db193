#include "scenario_truth.h"

#include <array>
#include <cmath>

#include "stewart/estimator/measurement_models.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"

namespace stewart::test {
namespace {

// One move of `distance` starting at t0: a trapezoidal velocity profile of
// peak `speed` whose ramps (duration ramp_s) are smoothsteps, so the
// acceleration is continuous. Returns {position, velocity, acceleration}.
struct Move {
  double t0_s, distance, speed, ramp_s;
};

Eigen::Vector3d EvalMove(const Move& m, double t_s) {
  const double v = std::copysign(m.speed, m.distance);
  const double T = std::abs(m.distance) / m.speed + m.ramp_s;
  const double tau = t_s - m.t0_s;
  const double Ta = m.ramp_s;
  if (tau <= 0.0) return {0.0, 0.0, 0.0};
  if (tau >= T) return {m.distance, 0.0, 0.0};
  if (tau < Ta) {
    const double u = tau / Ta;
    return {v * Ta * (u * u * u - 0.5 * u * u * u * u), v * (3 * u * u - 2 * u * u * u),
            v * 6 * u * (1 - u) / Ta};
  }
  if (tau <= T - Ta) return {v * Ta / 2 + v * (tau - Ta), v, 0.0};
  const double w = (T - tau) / Ta;
  return {m.distance - v * Ta * (w * w * w - 0.5 * w * w * w * w), v * (3 * w * w - 2 * w * w * w),
          -v * 6 * w * (1 - w) / Ta};
}

// The setpoint steps of the scenario, as moves within the velocity limits
// (xd, yd <= 0.015 m/s, zd <= 0.010 m/s).
const std::array<std::pair<int, Move>, 7> kMoves = {{
    {0, {0.0, 0.1, 0.0125, 1.0}},
    {0, {10.0, -0.1, 0.0125, 1.0}},
    {1, {10.0, 0.1, 0.0125, 1.0}},
    {1, {20.0, -0.1, 0.0125, 1.0}},
    {2, {20.0, 0.05, 0.008, 1.0}},
    {2, {30.0, 0.05, 0.008, 1.0}},
    {2, {40.0, -0.1, 0.008, 1.0}},
}};

// Small rotations: amplitude (rad), frequency (Hz), phase (rad).
constexpr std::array<std::array<double, 3>, 3> kWiggle = {{
    {0.010, 0.20, 0.0},
    {0.010, 0.13, 1.0},
    {0.015, 0.10, 2.0},
}};

SensorConfig WithSeed(SensorConfig sensors, unsigned seed) {
  sensors.seed = seed;
  return sensors;
}

}  // namespace

ScenarioTruth::ScenarioTruth(const StackConfig& config, unsigned seed, bool angular_motion,
                             const TruthDisturbance& disturbance)
    : config_(config),
      angular_motion_(angular_motion),
      disturbance_(disturbance),
      period_us_(static_cast<int64_t>(1e6 / config.sensors.rate_hz)),
      gyro_bias_radps_(config.sensors.gyro_bias_radps),
      sensor_model_(WithSeed(config.sensors, seed), config.actuators, config.platform.gravity_mps2),
      rng_(seed) {}

TruthState ScenarioTruth::AnalyticState(double t_s) const {
  TruthState s;
  s.q = config_.home_pose;
  for (const auto& [axis, move] : kMoves) {
    const Eigen::Vector3d p = EvalMove(move, t_s);
    s.q(axis) += p(0);
    s.qd(axis) += p(1);
    s.qdd(axis) += p(2);
  }
  if (angular_motion_) {
    for (int i = 0; i < 3; ++i) {
      const double a = kWiggle[i][0];
      const double w = 2.0 * M_PI * kWiggle[i][1];
      const double arg = w * t_s + kWiggle[i][2];
      s.q(3 + i) += a * std::sin(arg);
      s.qd(3 + i) += a * w * std::cos(arg);
      s.qdd(3 + i) += -a * w * w * std::sin(arg);
    }
  }
  return s;
}

TruthSample ScenarioTruth::Next() {
  TruthSample out;
  out.utime = next_utime_;
  const double dt_s = static_cast<double>(period_us_) * 1e-6;
  const TruthState analytic = AnalyticState(static_cast<double>(out.utime) * 1e-6);
  Vector6d w;
  for (int i = 0; i < 6; ++i) {
    w(i) = normal_(rng_) * (i < 3 ? disturbance_.accel_std_mps2 : disturbance_.angaccel_std_radps2);
  }
  out.state.q = analytic.q + d_;
  out.state.qd = analytic.qd + dd_;
  out.state.qdd = analytic.qdd + w;
  // The command is what the model needs for the analytic acceleration at the
  // true state, plus the lead-screw friction the actuators lose; w is the
  // unmodelled disturbance on top of it.
  const DynamicsTerms terms = EvaluateDynamics(config_.platform, out.state.q, out.state.qd);
  const Vector6d leg_speed_mps = terms.H.transpose() * out.state.qd;
  out.force_n = InverseDynamics(terms, analytic.qdd) +
                config_.actuators.viscous_friction_nspm * leg_speed_mps;
  out.gyro_bias_radps = gyro_bias_radps_;
  out.sensors = Sense(out.utime, out.state);

  d_ += dt_s * dd_ + 0.5 * dt_s * dt_s * w;
  dd_ += dt_s * w;
  const double walk = disturbance_.gyro_bias_walk_radps_per_sqrt_s * std::sqrt(dt_s);
  gyro_bias_radps_ += walk * Vector3d(normal_(rng_), normal_(rng_), normal_(rng_));
  next_utime_ += period_us_;
  return out;
}

SensorSample ScenarioTruth::Sense(int64_t utime, const TruthState& s) {
  // plant_sim's sensor model, exactly as the simulator samples it; only the
  // gyro bias's random walk (a disturbance the EKF models, for the
  // consistency tests) is added on top of the configured constant bias.
  const SensorReading r =
      sensor_model_.Sample(s.q, s.qd, s.qdd, InverseKinematics(config_.platform, s.q));
  SensorSample out;
  out.utime = utime;
  out.leg_length_m = r.leg_length_m;
  out.gyro_radps = r.gyro_radps + (gyro_bias_radps_ - config_.sensors.gyro_bias_radps);
  out.accel_mps2 = r.accel_mps2;
  out.has_orientation = r.has_orientation;
  out.orientation_rpy_rad = r.orientation_rpy_rad;
  return out;
}

}  // namespace stewart::test
