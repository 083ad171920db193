#include "stewart/controller/scenario.h"

#include <algorithm>
#include <cmath>

#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Quintic s(tau) with s(0)=0, s(1)=1 and zero first and second derivatives at
// both ends (minimum-jerk point-to-point move).
struct Quintic {
  double s, ds, dds;  // d/dtau
};
Quintic MinimumJerk(double tau) {
  const double t2 = tau * tau, t3 = t2 * tau, t4 = t3 * tau, t5 = t4 * tau;
  return {10.0 * t3 - 15.0 * t4 + 6.0 * t5, 30.0 * t2 - 60.0 * t3 + 30.0 * t4,
          60.0 * tau - 180.0 * t2 + 120.0 * t3};
}

}  // namespace

Setpoint EvaluateSegment(const ScenarioSegment& seg, double t_s) {
  Setpoint sp;
  switch (seg.type) {
    case SegmentType::kStep:
      sp.q_des = seg.q_des;
      break;
    case SegmentType::kSine: {
      const double w = 2.0 * kPi / seg.period_s;
      const double tau = t_s - seg.start_s;
      for (int j = 0; j < kNumAxes; ++j) {
        const double angle = w * tau + seg.phase_rad(j);
        sp.q_des(j) = seg.center(j) + seg.amplitude(j) * std::sin(angle);
        sp.qd_des(j) = seg.amplitude(j) * w * std::cos(angle);
        sp.qdd_des(j) = -seg.amplitude(j) * w * w * std::sin(angle);
      }
      break;
    }
    case SegmentType::kMove: {
      const double T = seg.end_s - seg.start_s;
      const double tau = std::clamp((t_s - seg.start_s) / T, 0.0, 1.0);
      const Quintic s = MinimumJerk(tau);
      const Vector6d delta = seg.q_des - seg.q_from;
      sp.q_des = seg.q_from + s.s * delta;
      if (tau < 1.0) {
        sp.qd_des = (s.ds / T) * delta;
        sp.qdd_des = (s.dds / (T * T)) * delta;
      }
      break;
    }
  }
  return sp;
}

Scenario::Scenario(std::string name, double duration_s, std::vector<ScenarioSegment> segments)
    : name_(std::move(name)), duration_s_(duration_s), segments_(std::move(segments)) {}

Setpoint Scenario::Evaluate(double t_s) const {
  const double t = std::max(t_s, 0.0);
  // Segment with the last start_s <= t (segments_[0].start_s == 0).
  const auto next = std::upper_bound(
      segments_.begin(), segments_.end(), t,
      [](double value, const ScenarioSegment& seg) { return value < seg.start_s; });
  return EvaluateSegment(*(next - 1), t);
}

std::optional<double> FirstTimeOutsideWorkspace(const Scenario& scenario,
                                                const PlatformParams& platform, double step_s) {
  const long steps = static_cast<long>(std::ceil(scenario.duration_s() / step_s));
  for (long k = 0; k <= steps; ++k) {
    const double t = std::min(static_cast<double>(k) * step_s, scenario.duration_s());
    if (!PoseInWorkspace(platform, scenario.Evaluate(t).q_des)) return t;
  }
  return std::nullopt;
}

}  // namespace stewart
