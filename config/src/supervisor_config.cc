#include <sstream>

#include "stewart/config/sections.h"

namespace stewart {

safety::SupervisorConfig ParseSupervisorConfig(const ConfigNode& supervisor) {
  safety::SupervisorConfig c;
  c.arming_ramp_s = supervisor.NonNegativeDouble("arming_ramp_s");
  c.auto_arm = supervisor.Bool("auto_arm");
  c.fallback_latch_s = supervisor.NonNegativeDouble("fallback_latch_s");
  c.stall_check = supervisor.Bool("stall_check");
  c.hold_drive_off = supervisor.Bool("hold_drive_off");
  c.hold_brake_s = supervisor.NonNegativeDouble("hold_brake_s");
  c.heartbeat_timeout_s = supervisor.PositiveDouble("heartbeat_timeout_s");
  c.operator_timeout_s = supervisor.NonNegativeDouble("operator_timeout_s");
  c.operator_time_window_s = supervisor.PositiveDouble("operator_time_window_s");
  std::istringstream names(supervisor.String("required_processes"));
  c.required_processes.clear();
  for (std::string name; names >> name;) c.required_processes.push_back(name);
  return c;
}

}  // namespace stewart
