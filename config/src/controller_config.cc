#include "stewart/config/sections.h"

namespace stewart {

ControllerConfig ParseControllerConfig(const ConfigNode& controller) {
  ControllerConfig c;
  c.kp = controller.Vec6("kp");
  c.kd = controller.Vec6("kd");
  if ((c.kp.array() <= 0.0).any()) controller.Fail("kp", "every gain must be positive");
  if ((c.kd.array() <= 0.0).any()) controller.Fail("kd", "every gain must be positive");
  if (controller.Has("compensate_disturbance")) {
    c.compensate_disturbance = controller.Bool("compensate_disturbance");
  }
  if (controller.Has("compensate_friction")) {
    c.compensate_friction = controller.Bool("compensate_friction");
  }
  if (controller.Has("stale_age_s")) c.stale_age_s = controller.PositiveDouble("stale_age_s");
  return c;
}

}  // namespace stewart
