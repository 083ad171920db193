#pragma once
// Time-indexed setpoint scenarios (config/scenarios/*.yaml, format in
// docs/controller.md). Time t is in seconds from the first state the
// controller receives.
//
//   name: paper
//   duration_s: 40.0
//   segments:                        # start_s strictly increasing, first 0
//     - {start_s: 0.0, type: step, q_des: [0.1, 0, 0.4, 0, 0, 0]}
//     - {start_s: 10.0, type: sine, center: [...], amplitude: [...],
//        period_s: 20.0, phase_deg: [...]}
//     - {start_s: 30.0, type: move, q_des: [...]}   # minimum-jerk from the
//                                                  # previous segment's end
//                                                  # pose (or q_from: [...])
//
// A segment lasts until the next one starts; the last one also holds after
// duration_s (the controller keeps running unless told to exit at the end).
#include <optional>
#include <string>
#include <vector>

#include "stewart/controller/setpoint.h"
#include "stewart/model/platform_params.h"

namespace stewart {

enum class SegmentType { kStep, kSine, kMove };

struct ScenarioSegment {
  SegmentType type = SegmentType::kStep;
  double start_s = 0.0;
  double end_s = 0.0;  ///< next start, or duration_s for the last one
  /// step: held pose; move: target pose.
  Vector6d q_des = Vector6d::Zero();
  /// move: q_from of the file, else the pose at the end of the previous segment.
  Vector6d q_from = Vector6d::Zero();
  /// sine: q = center + amplitude sin(2 pi (t - start_s) / period_s + phase).
  Vector6d center = Vector6d::Zero();
  Vector6d amplitude = Vector6d::Zero();
  Vector6d phase_rad = Vector6d::Zero();
  double period_s = 1.0;
};

/// The setpoint of one segment at t (s from the scenario's start).
Setpoint EvaluateSegment(const ScenarioSegment& segment, double t_s);

class Scenario {
 public:
  Scenario(std::string name, double duration_s, std::vector<ScenarioSegment> segments);

  const std::string& name() const { return name_; }
  double duration_s() const { return duration_s_; }
  const std::vector<ScenarioSegment>& segments() const { return segments_; }

  /// The setpoint at t (s from the start; t < 0 is treated as 0). No heap
  /// allocation.
  Setpoint Evaluate(double t_s) const;

 private:
  std::string name_;
  double duration_s_;
  std::vector<ScenarioSegment> segments_;
};

/// First time (sampled every `step_s` over [0, duration_s]) at which the
/// scenario leaves the workspace (PoseInWorkspace), if any.
std::optional<double> FirstTimeOutsideWorkspace(const Scenario& scenario,
                                                const PlatformParams& platform,
                                                double step_s = 0.01);

}  // namespace stewart
