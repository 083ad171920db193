#include "stewart/stack/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "stewart/common/health_counters.h"
#include "stewart/common/signals.h"
#include "stewart/controller/controller_process.h"
#include "stewart/estimator/estimator_process.h"
#include "stewart/model/shared_dynamics_terms.h"
#include "stewart/plant_sim/disturbance_source.h"
#include "stewart/plant_sim/ode_integrator.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"
#include "stewart/safety/constraint_set.h"
#include "stewart/safety/safety_process.h"

namespace stewart {
namespace {

// Calls visit(name, margin) for every configured limit, in LimitNames order.
template <typename Visit>
void ForEachLimit(const SafetyConfig& s, const Vector6d& q, const Vector6d& qd, Visit&& visit) {
  auto name = [](int axis, const char* what) { return std::string(kAxisNames[axis]) + what; };
  for (const PositionLimitConfig& l : s.position_limits) {
    if (l.upper) visit(name(l.axis, "_upper"), *l.upper - q(l.axis));
    if (l.lower) visit(name(l.axis, "_lower"), q(l.axis) - *l.lower);
  }
  for (const VelocityLimitConfig& l : s.velocity_limits) {
    if (l.upper) visit(name(l.axis, "d_upper"), *l.upper - qd(l.axis));
    if (l.lower) visit(name(l.axis, "d_lower"), qd(l.axis) - *l.lower);
  }
}

void TrackLimitExcess(const SafetyConfig& s, const Vector6d& q, const Vector6d& qd,
                      ClosedLoopSummary* out) {
  std::size_t i = 0;
  ForEachLimit(s, q, qd, [&](const std::string& name, double margin) {
    LimitMargin& m = out->limit_margins[i++];
    m.worst_margin = std::min(m.worst_margin, margin);
    if (-margin > out->max_limit_excess) {
      out->max_limit_excess = -margin;
      out->max_limit_excess_name = name;
      std::replace(out->max_limit_excess_name.begin(), out->max_limit_excess_name.end(), '_', ' ');
    }
  });
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

std::vector<std::string> LimitNames(const SafetyConfig& safety) {
  std::vector<std::string> names;
  ForEachLimit(safety, Vector6d::Zero(), Vector6d::Zero(),
               [&](const std::string& name, double) { names.push_back(name); });
  return names;
}

ClosedLoopSummary RunClosedLoop(const StackConfig& config, const Scenario& scenario,
                                const ClosedLoopOptions& options, std::ostream* csv) {
  SensorConfig sensors = config.sensors;
  sensors.seed = static_cast<unsigned>(options.seed);
  PlantTruth truth = options.truth ? *options.truth : TruthOfConfig(config);
  truth.sensors.seed = sensors.seed;
  truth.sensors.rate_hz = sensors.rate_hz;
  Plant plant(PlantModelOf(truth, config), OdeOptionsFrom(config.plant_sim));
  plant.Reset(0.0, truth.initial_pose, truth.initial_velocity);
  SensorModel sensor_model(truth.sensors, truth.actuators, truth.platform.gravity_mps2,
                           truth.sensor_errors);
  DisturbanceSource disturbance(truth.disturbance, truth.sensors.seed);
  const safety::LegStrokeBand stroke_band =
      safety::LegStrokeBandOf(config.platform, config.safety.leg_stroke);
  // The processes' own classes, stepped in the order lockstep runs them:
  // sample -> estimator -> controller -> safety -> plant.
  HealthCounters estimator_counters("estimator"), controller_counters("controller"),
      safety_counters("safety");
  EstimatorProcess estimator(config.platform, config.actuators, sensors, config.estimator,
                             config.home_pose, &estimator_counters, config.lcm.time_plausibility);
  ControllerProcess controller(config.platform, config.controller, config.home_pose, scenario,
                               &controller_counters, config.lcm.time_plausibility);
  // A simulation: the supervisor arms by itself, as tools/launch.sh has it
  // do in simulation (no operator in the loop).
  safety::SupervisorConfig supervisor = config.supervisor;
  supervisor.auto_arm = true;
  safety::SafetyProcess safety(config.platform, config.safety, config.actuators, supervisor,
                               options.reference, &safety_counters, config.lcm.time_plausibility);
  std::shared_ptr<SharedDynamicsTerms> shared_terms;
  if (options.share_model_terms) {
    shared_terms = std::make_shared<SharedDynamicsTerms>(config.platform);
    estimator.ShareModelTerms(shared_terms);
    controller.ShareModelTerms(shared_terms);
    safety.ShareModelTerms(shared_terms);
  }

  const std::int64_t period_us = std::llround(1e6 / sensors.rate_hz);
  const long ticks = std::lround(options.duration_s * 1e6 / static_cast<double>(period_us));
  ClosedLoopSummary out;
  out.period_s = static_cast<double>(period_us) * 1e-6;
  for (std::string& name : LimitNames(config.safety)) out.limit_margins.push_back({name});
  // Plant::Advance throws when SUNDIALS fails: the run ends there, reported.
  bool drive_off = true;  // power-on: DISARMED until the first command says otherwise
  auto advance = [&](const Vector6d& force_n) {
    plant.SetActuatorsOff(drive_off);
    if (!drive_off) plant.SetForceCommand(force_n);
    plant.SetExternalWrench(disturbance.WrenchAt(plant.time_s()));
    try {
      plant.Advance(static_cast<double>(period_us) * 1e-6);
    } catch (const std::runtime_error& e) {
      out.failure = e.what();
      return false;
    }
    return true;
  };
  double sq_q = 0.0, sq_qd = 0.0;
  Vector6d sq_tracking = Vector6d::Zero();
  long estimated_ticks = 0;
  if (csv) {
    *csv << "t";
    for (const char* prefix : {"q_", "qd_", "qest_", "qdest_"})
      for (const std::string_view a : kAxisNames) *csv << ',' << prefix << a;
    for (const char* prefix : {"fdes_", "fsafe_"})
      for (int i = 1; i <= 6; ++i) *csv << ',' << prefix << i;
    *csv << ",case,h_pos,h_vel";
    for (const char* prefix : {"dest_", "dstd_"})
      for (const std::string_view a : kAxisNames) *csv << ',' << prefix << a;
    *csv << ",psi_v,ekf_events\n";
  }
  Vector6d f_safe = Vector6d::Zero();  // held by the plant until the next command
  for (long k = 0; k < ticks; ++k) {
    const std::int64_t utime = k * period_us;
    const Vector6d q_true = plant.q(), qd_true = plant.qd();
    const PlantRates& rates = plant.EvaluateRates();
    const SensorReading r =
        sensor_model.Sample(q_true, qd_true, rates.x_dot.segment<6>(6), rates.terms.leg_length_m);
    if (config.safety.leg_stroke.enabled) {
      // The plant's own leg lengths at this state (its model terms).
      const Vector6d& leg_length_m = rates.terms.leg_length_m;
      const double inside_m = std::min((leg_length_m.array() - stroke_band.lower_m).minCoeff(),
                                       (stroke_band.upper_m - leg_length_m.array()).minCoeff());
      if (std::isfinite(inside_m)) {
        out.leg_stroke_worst_margin_m = std::min(out.leg_stroke_worst_margin_m, inside_m);
      }
    }
    StateSample state;
    bool has_state = false;
    if (options.perfect_state) {
      StateSample true_state;
      true_state.utime = true_state.sample_utime = utime;
      true_state.seq = k;
      true_state.q = q_true;
      true_state.qd = qd_true;
      true_state.status = kStateValid | kStateGroundTruth;
      has_state = estimator.OnTruth(true_state, &state);
    } else {
      SensorSample sample;
      sample.utime = utime;
      sample.leg_length_m = r.leg_length_m;
      sample.gyro_radps = r.gyro_radps;
      sample.accel_mps2 = r.accel_mps2;
      sample.has_orientation = r.has_orientation;
      sample.orientation_rpy_rad = r.orientation_rpy_rad;
      // As plant_sim's STATUS_ACTUATORS_OFF: the legs are held (the drive
      // off, or its return not yet in effect under a command delay).
      sample.drive_off = plant.actuators_off();
      has_state = estimator.OnSensor(sample, &state);
      if (has_state) {
        sq_q += (state.q - q_true).head<3>().squaredNorm();
        sq_qd += (state.qd - qd_true).head<3>().squaredNorm();
        ++estimated_ticks;
      }
    }
    if (!has_state) {
      if (!advance(f_safe)) break;
      continue;
    }
    ControllerProcessOutput nominal;
    const bool has_nominal = controller.OnState(state, &nominal) == ControllerVerdict::kPublished;
    // A forger's nominal for this sample reaches safety in the controller's place.
    if (has_nominal && options.forge_nominal) options.forge_nominal(k, &nominal.command.force_n);
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
    if (has_safe) {
      drive_off = (safe.command.flags & kCommandDriveOff) != 0;
      // The controller's scenario runs on the supervisor's motion clock,
      // which it receives after this step (as over LCM in lockstep).
      const safety::Supervisor& sup = safety.supervisor();
      controller.OnSupervisor(sup.utime(), sup.motion_time_us(),
                              sup.state() == safety::SupervisorState::kArming ||
                                  sup.state() == safety::SupervisorState::kArmed);
    }
    const safety::SafetyDiagnostics* d = has_safe ? safe.diagnostics : nullptr;
    if (d != nullptr) {
      ++out.case_ticks[static_cast<size_t>(d->filter_case)];
      if (d->infeasible) ++out.infeasible_ticks;
      if (d->flags & safety::kFlagNominalBounded) ++out.nominal_bounded_ticks;
      if (d->flags & safety::kFlagPerBarrier) ++out.per_barrier_ticks;
    }
    if (has_safe && safe.fallback_reason != 0) ++out.fallback_ticks;
    const double f_max = f_safe.cwiseAbs().maxCoeff();
    out.max_force_n = std::max(out.max_force_n, f_max);
    if (f_max > config.actuators.force_limit_n) ++out.saturated_ticks;
    if (has_safe) {
      ForceCommand applied = safe.command;
      applied.force_n = f_safe;
      // In process every answer comes before the next sample: no sample
      // ever waits for one here, so no estimate is released.
      StateSample released;
      estimator.OnCommand(applied, &released);
    }
    if (csv) {
      *csv << static_cast<double>(utime) * 1e-6;
      const std::array<const Vector6d*, 6> columns{
          &q_true, &qd_true, &state.q, &state.qd, &nominal.command.force_n, &f_safe};
      for (const Vector6d* v : columns)
        for (int i = 0; i < 6; ++i) *csv << ',' << (*v)(i);
      *csv << ',' << (d ? static_cast<int>(d->filter_case) : -1) << ','
           << (d ? d->barriers.h_pos : 0.0) << ',' << (d ? d->barriers.h_vel : 0.0);
      for (const Vector6d* v : {&state.disturbance, &state.disturbance_std})
        for (int i = 0; i < 6; ++i) *csv << ',' << (*v)(i);
      *csv << ',' << (d ? d->barriers.psi_v : 0.0) << ',' << estimator.last_update_events() << '\n';
    }
    if (!advance(f_safe)) break;
    const Vector6d q1 = plant.q(), qd1 = plant.qd();
    out.q_max = out.q_max.cwiseMax(q1);
    out.q_min = out.q_min.cwiseMin(q1);
    out.qd_max = out.qd_max.cwiseMax(qd1);
    out.qd_min = out.qd_min.cwiseMin(qd1);
    TrackLimitExcess(config.safety, q1, qd1, &out);
    ++out.ticks;
    if (!q1.allFinite() || !qd1.allFinite()) {
      out.failure = "non-finite plant state";
      break;
    }
  }
  if (shared_terms) {
    out.model_evaluations = shared_terms->evaluations();
    out.model_evaluations_shared = shared_terms->hits();
  }
  out.endstop_hits = plant.counters().endstop_hits;
  out.armed_s = static_cast<double>(safety.supervisor().motion_time_us()) * 1e-6;
  out.stiff_fallbacks = plant.counters().stiff_fallbacks;
  out.estimator_rejections = estimator_counters.rejected_inputs();
  if (!out.failure.empty()) return out;
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
  const long n_translation = out.inside_ticks[0] + out.inside_ticks[1] + out.inside_ticks[2];
  if (n_translation > 0) {
    out.rms_translation_tracking_inside_m =
        std::sqrt(sq_tracking.head<3>().sum() / static_cast<double>(n_translation));
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
                "%ld/%ld/%ld/%ld/%ld/%ld; saturated ticks %ld, max |F*| %.1f N; "
                "nominal bounded ticks %ld, per-barrier ticks %ld\n",
                s.max_limit_excess, s.max_limit_excess_name.c_str(), s.ticks, s.case_ticks[0],
                s.case_ticks[1], s.case_ticks[2], s.case_ticks[3], s.case_ticks[4], s.case_ticks[5],
                s.saturated_ticks, s.max_force_n, s.nominal_bounded_ticks, s.per_barrier_ticks);
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
  if (s.leg_stroke_worst_margin_m < 1e8) {
    std::snprintf(line, sizeof line,
                  "legs: closest %.2f mm inside the leg-stroke barriers' band (negative: beyond "
                  "it); end-stop hits %ld\n",
                  s.leg_stroke_worst_margin_m * 1e3, s.endstop_hits);
    o << line;
  }
  return o.str();
}

}  // namespace stewart
