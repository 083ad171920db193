#pragma once
// One sample of a recorded run, as the fit needs it.
#include <cstdint>

#include "stewart/model/types.h"

namespace stewart::identify {

/// The platform's state at one sensor sample and the leg forces commanded for
/// it. The force acts from this sample until the next (the plant holds a
/// command until the next one), so it is paired with the state it answers.
struct IdentificationSample {
  std::int64_t utime = 0;               ///< sample time (us)
  Vector6d q = Vector6d::Zero();        ///< pose of {P} in {B} (m, rad)
  Vector6d qd = Vector6d::Zero();       ///< its time derivative (m/s, rad/s)
  Vector6d force_n = Vector6d::Zero();  ///< commanded leg forces (N), the safety filter's output
};

}  // namespace stewart::identify
