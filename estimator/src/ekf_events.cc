#include "stewart/estimator/ekf_types.h"

namespace stewart {

const char* EkfEventName(EkfEvent event) {
  switch (event) {
    case kEventInitialized:
      return "initialized";
    case kEventReinitTimeGap:
      return "reinit_time_gap";
    case kEventDiverged:
      return "divergences";
    case kEventNoCommand:
      return "predict_without_command";
    case kRejectTime:
      return "non_increasing_time";
    case kRejectLegsNonFinite:
      return "legs_non_finite";
    case kRejectLegsRange:
      return "legs_out_of_range";
    case kRejectGyroInvalid:
      return "gyro_invalid";
    case kRejectAccelInvalid:
      return "accel_invalid";
    case kRejectOrientationInvalid:
      return "orientation_invalid";
    case kGateLegs:
      return "gated_legs";
    case kGateGyro:
      return "gated_gyro";
    case kGateAccel:
      return "gated_accel";
    case kGateOrientation:
      return "gated_orientation";
    case kRejectInitFailed:
      return "init_fk_failed";
    case kEventDisturbanceJump:
      return "disturbance_jumps";
    case kEventLegsHeld:
      return "predict_legs_held";
    case kEventPoseReopened:
      return "pose_reopened";
    case kEventRatesReopened:
      return "rates_reopened";
  }
  return "unknown";
}

bool IsRejection(EkfEvent event) { return event >= kRejectTime && event <= kRejectInitFailed; }

}  // namespace stewart
