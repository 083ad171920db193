#pragma once
// The viewer's conversions from the stack's messages to the library's
// samples (stewart/viewer/snapshot.h), shared by the live bus and the log.
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/operator_command_t.hpp"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/viewer/snapshot.h"

namespace stewart::viewer {

StateSample ToSample(const state_t& msg);
SetpointSample ToSample(const setpoint_t& msg);
ForceSample ToSample(const force_command_t& msg);
DiagnosticsSample ToSample(const safety_diagnostics_t& msg);
HealthSample ToSample(const health_t& msg);
SupervisorSample ToSample(const supervisor_state_t& msg);
OperatorSample ToSample(const operator_command_t& msg, bool authentic);

}  // namespace stewart::viewer
