#include "stewart/stack/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "stewart/common/health_counters.h"
#include "stewart/common/signals.h"
#include "stewart/controller/controller_process.h"
#include "stewart/estimator/estimator_process.h"
#include "stewart/plant_sim/ode_integrator.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"
#include "stewart/safety/safety_process.h"

namespace stewart {
namespace {

void TrackLimitExcess(const SafetyConfig& s, const Vector6d& q, const Vector6d& qd,
                      ClosedLoopSummary* out) {
  auto consider = [&](double excess, int axis, const char* what) {
    if (excess > out->max_limit_excess) {
      out->max_limit_excess = excess;
      out->max_limit_excess_name = std::string(kAxisNames[axis]) + what;
    }
  };
  for (const PositionLimitConfig& l : s.position_limits) {
    if (l.upper) consider(q(l.axis) - *l.upper, l.axis, " upper");
    if (l.lower) consider(*l.lower - q(l.axis), l.axis, " lower");
  }
  for (const VelocityLimitConfig& l : s.velocity_limits) {
    if (l.upper) consider(qd(l.axis) - *l.upper, l.axis, "d upper");
    if (l.lower) consider(*l.lower - qd(l.axis), l.axis, "d lower");
  }
}

// Whether the setpoint of `axis` lies within that axis' configured limits.
bool SetpointInside(const SafetyConfig& s, int axis, double q_des) {
  for (const PositionLimitConfig& l : s.position_limits) {
    if (l.axis != axis) continue;
    if (l.upper && q_des > *l.upper) return false;
    if (l.lower && q_des < *l.lower) return false;
  }
  return true;
}

}  // namespace

ClosedLoopSummary RunClosedLoop(const StackConfig& config, const Scenario& scenario,
                                const ClosedLoopOptions& options, std::ostream* csv) {
  SensorConfig sensors = config.sensors;
  sensors.seed = static_cast<unsigned>(options.seed);
  Plant plant(PlantModel{config.platform, config.actuators}, OdeOptionsFrom(config.plant_sim));
  plant.Reset(0.0, config.plant_sim.initial_pose, config.plant_sim.initial_velocity);
  SensorModel sensor_model(sensors, config.actuators, config.platform.gravity_mps2);
  // The processes' own classes, stepped in the order lockstep runs them:
  // sample -> estimator -> controller -> safety -> plant.
  HealthCounters estimator_counters("estimator"), controller_counters("controller"),
      safety_counters("safety");
  EstimatorProcess estimator(config.platform, config.actuators, sensors, config.estimator,
                             config.home_pose, &estimator_counters);
  ControllerProcess controller(config.platform, config.controller, config.home_pose, scenario,
                               &controller_counters);
  safety::SafetyProcess safety(config.platform, config.safety, config.actuators, options.reference,
                               &safety_counters);

  const std::int64_t period_us = std::llround(1e6 / sensors.rate_hz);
  const long ticks = std::lround(options.duration_s * 1e6 / static_cast<double>(period_us));
  ClosedLoopSummary out;
  out.period_s = static_cast<double>(period_us) * 1e-6;
  double sq_q = 0.0, sq_qd = 0.0;
  Vector6d sq_tracking = Vector6d::Zero();
  long estimated_ticks = 0;
  if (csv) {
    *csv << "t";
    for (const char* prefix : {"q_", "qd_", "qest_", "qdest_"})
      for (const std::string_view a : kAxisNames) *csv << ',' << prefix << a;
    for (const char* prefix : {"fdes_", "fsafe_"})
      for (int i = 1; i <= 6; ++i) *csv << ',' << prefix << i;
    *csv << ",case,h_pos,h_vel\n";
  }
  Vector6d f_safe = Vector6d::Zero();  // held by the plant until the next command
  for (long k = 0; k < ticks; ++k) {
    const std::int64_t utime = k * period_us;
    const Vector6d q_true = plant.q(), qd_true = plant.qd();
    const PlantRates& rates = plant.EvaluateRates();
    const SensorReading r =
        sensor_model.Sample(q_true, qd_true, rates.x_dot.segment<6>(6), rates.terms.leg_length_m);
    StateSample state;
    bool has_state = false;
    if (options.perfect_state) {
      StateSample truth;
      truth.utime = truth.sample_utime = utime;
      truth.seq = k;
      truth.q = q_true;
      truth.qd = qd_true;
      truth.status = kStateValid | kStateGroundTruth;
      has_state = estimator.OnTruth(truth, &state);
    } else {
      SensorSample sample;
      sample.utime = utime;
      sample.leg_length_m = r.leg_length_m;
      sample.gyro_radps = r.gyro_radps;
      sample.accel_mps2 = r.accel_mps2;
      sample.has_orientation = r.has_orientation;
      sample.orientation_rpy_rad = r.orientation_rpy_rad;
      has_state = estimator.OnSensor(sample, &state);
      if (has_state) {
        sq_q += (state.q - q_true).head<3>().squaredNorm();
        sq_qd += (state.qd - qd_true).head<3>().squaredNorm();
        ++estimated_ticks;
      }
    }
    if (!has_state) {
      plant.Advance(static_cast<double>(period_us) * 1e-6);
      continue;
    }
    ControllerProcessOutput nominal;
    const bool has_nominal =
        controller.OnState(state, &nominal) == ControllerVerdict::kPublished;
    // Safety sees the state first, then the nominal command derived from it
    // (always delivered: it shows the controller is alive). The plant, as in
    // lockstep, applies the first command that answers this sample.
    safety::SafetyOutput from_state, from_nominal;
    const bool state_answered = safety.OnState(state, &from_state);
    const bool nominal_answered = has_nominal && safety.OnNominal(nominal.command, &from_nominal);
    const bool has_safe = state_answered || nominal_answered;
    const safety::SafetyOutput& safe = state_answered ? from_state : from_nominal;
    const bool filtered = has_safe && has_nominal && safe.fallback_reason == 0;
    if (filtered) {
      f_safe = options.no_filter ? nominal.command.force_n : safe.command.force_n;
      ++out.filtered_ticks;
      const double correction = (f_safe - nominal.command.force_n).norm();
      out.sum_correction_n += correction;
      if (correction > 0.0) ++out.active_ticks;
      const Setpoint& setpoint = nominal.setpoint_echo.setpoint;
      for (int a = 0; a < 6; ++a) {
        if (!SetpointInside(config.safety, a, setpoint.q_des(a))) continue;
        ++out.inside_ticks[static_cast<size_t>(a)];
        const double e = q_true(a) - setpoint.q_des(a);
        sq_tracking(a) += e * e;
      }
    } else if (has_safe) {
      f_safe = safe.command.force_n;
    }
    const safety::SafetyDiagnostics* d = has_safe ? safe.diagnostics : nullptr;
    if (d != nullptr) {
      ++out.case_ticks[static_cast<size_t>(d->filter_case)];
      if (d->infeasible) ++out.infeasible_ticks;
    }
    const double f_max = f_safe.cwiseAbs().maxCoeff();
    out.max_force_n = std::max(out.max_force_n, f_max);
    if (f_max > config.actuators.force_limit_n) ++out.saturated_ticks;
    if (has_safe) {
      ForceCommand applied = safe.command;
      applied.force_n = f_safe;
      estimator.OnCommand(applied);
    }
    if (csv) {
      *csv << static_cast<double>(utime) * 1e-6;
      const std::array<const Vector6d*, 6> columns{&q_true,  &qd_true,
                                                   &state.q, &state.qd,
                                                   &nominal.command.force_n, &f_safe};
      for (const Vector6d* v : columns)
        for (int i = 0; i < 6; ++i) *csv << ',' << (*v)(i);
      *csv << ',' << (d ? static_cast<int>(d->filter_case) : -1) << ','
           << (d ? d->barriers.h_pos : 0.0) << ',' << (d ? d->barriers.h_vel : 0.0) << '\n';
    }
    plant.SetForceCommand(f_safe);
    plant.Advance(static_cast<double>(period_us) * 1e-6);
    const Vector6d q1 = plant.q(), qd1 = plant.qd();
    out.q_max = out.q_max.cwiseMax(q1);
    out.q_min = out.q_min.cwiseMin(q1);
    out.qd_max = out.qd_max.cwiseMax(qd1);
    out.qd_min = out.qd_min.cwiseMin(qd1);
    TrackLimitExcess(config.safety, q1, qd1, &out);
    ++out.ticks;
    if (!q1.allFinite() || !qd1.allFinite()) return out;
  }
  out.q_final = plant.q();
  // The first initialisation is the start, not a restart.
  out.estimator_reinits =
      std::max<long>(0, static_cast<long>(estimator_counters.counter("initialized")) - 1);
  if (estimated_ticks > 0) {
    out.rms_q_error = std::sqrt(sq_q / static_cast<double>(estimated_ticks));
    out.rms_qd_error = std::sqrt(sq_qd / static_cast<double>(estimated_ticks));
  }
  for (int a = 0; a < 6; ++a) {
    const long n = out.inside_ticks[static_cast<size_t>(a)];
    if (n > 0)
      out.rms_tracking_error_inside(a) = std::sqrt(sq_tracking(a) / static_cast<double>(n));
  }
  out.completed = true;
  return out;
}

std::string FormatSummary(const StackConfig& config, const ClosedLoopSummary& s) {
  std::ostringstream o;
  char line[512];
  o << "axis      q_min      q_max   limit |    qd_min     qd_max   limit\n";
  for (int a = 0; a < 6; ++a) {
    std::string pos_limit = "-", vel_limit = "-";
    for (const PositionLimitConfig& l : config.safety.position_limits)
      if (l.axis == a && l.upper) pos_limit = std::to_string(*l.upper).substr(0, 6);
    for (const VelocityLimitConfig& l : config.safety.velocity_limits)
      if (l.axis == a && l.upper) vel_limit = std::to_string(*l.upper).substr(0, 6);
    std::snprintf(line, sizeof line, "%-5s %10.5f %10.5f %7s | %9.5f %10.5f %7s\n",
                  std::string(kAxisNames[a]).c_str(), s.q_min(a), s.q_max(a), pos_limit.c_str(),
                  s.qd_min(a), s.qd_max(a), vel_limit.c_str());
    o << line;
  }
  std::snprintf(line, sizeof line,
                "worst excess %.3g (%s); ticks %ld; cases none/p/v/both/infeasible/fallback "
                "%ld/%ld/%ld/%ld/%ld/%ld; saturated ticks %ld, max |F*| %.1f N\n",
                s.max_limit_excess, s.max_limit_excess_name.c_str(), s.ticks, s.case_ticks[0],
                s.case_ticks[1], s.case_ticks[2], s.case_ticks[3], s.case_ticks[4], s.case_ticks[5],
                s.saturated_ticks, s.max_force_n);
  o << line;
  std::snprintf(line, sizeof line,
                "estimator: rms |q-q_true| %.3g m, rms |qd-qd_true| %.3g m/s, re-inits %ld; "
                "final q [%.4f %.4f %.4f %.4f %.4f %.4f]\n",
                s.rms_q_error, s.rms_qd_error, s.estimator_reinits, s.q_final(0), s.q_final(1),
                s.q_final(2), s.q_final(3), s.q_final(4), s.q_final(5));
  o << line;
  std::snprintf(line, sizeof line,
                "filter (%s): active %.2f s of %ld filtered ticks, mean |F*-F_des| %.4g N; "
                "rms tracking error where the setpoint is inside the limits: x %.4g y %.4g "
                "z %.4g m (%ld/%ld/%ld ticks)\n",
                ToString(config.safety.variant).c_str(), s.active_time_s(), s.filtered_ticks,
                s.mean_correction_n(), s.rms_tracking_error_inside(0),
                s.rms_tracking_error_inside(1), s.rms_tracking_error_inside(2), s.inside_ticks[0],
                s.inside_ticks[1], s.inside_ticks[2]);
  o << line;
  return o.str();
}

}  // namespace stewart
