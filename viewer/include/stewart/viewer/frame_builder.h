#pragma once
// Turns the newest values (ViewerSnapshot) into the JSON the page draws.
// Everything geometric is decided here, from the model, so the page does no
// kinematics: leg lengths, joint positions in {B}, how much of its stroke
// each leg uses. The page only places meshes and writes numbers.
#include <nlohmann/json.hpp>
#include <string>

#include "stewart/model/platform_params.h"
#include "stewart/safety/safety_config.h"
#include "stewart/viewer/snapshot.h"
#include "stewart/viewer/viewer_config.h"

namespace stewart::viewer {

/// What the page is connected to, sent once per connection ("hello").
struct SessionInfo {
  bool from_log = false;          ///< playing a recorded log, not the live bus
  bool operator_enabled = false;  ///< the page may send operator commands
  int64_t operator_id = 0;        ///< the viewer's operator_id (0 when read-only)
  double log_start_s = 0.0;       ///< log: first and last stack time (s)
  double log_end_s = 0.0;
};

class FrameBuilder {
 public:
  /// A leg within this share of its stroke from either end is drawn in the
  /// warning colour.
  static constexpr double kStrokeWarningShare = 0.1;

  FrameBuilder(PlatformParams platform, SafetyConfig safety, Vector6d home_pose,
               ViewerConfig config);

  /// The static part: geometry, limits, mode. Once per connection.
  nlohmann::json Hello(const SessionInfo& session) const;
  /// One frame: the snapshot with the kinematics the page draws.
  nlohmann::json Frame(const ViewerSnapshot& snapshot) const;

 private:
  PlatformParams platform_;
  SafetyConfig safety_;
  Vector6d home_pose_;
  ViewerConfig config_;
};

/// Names of the message enums, for the panels (UNKNOWN out of range).
const char* SupervisorStateName(int state);
const char* HealthStateName(int state);
const char* FilterCaseName(int active_case);

}  // namespace stewart::viewer
