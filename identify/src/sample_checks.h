#pragma once
// The checks every bring-up procedure makes on a device sample before it acts
// on it (actuator_procedure.cc, stroke_end_procedure.cc): one place, so the
// procedures refuse the same samples for the same reasons.
#include <cstdint>
#include <optional>
#include <string>

#include "stewart/identify/actuator_device.h"

namespace stewart::identify::detail {

/// Why `s` must not be acted on, or nullopt: its time must be after
/// `previous_utime` (when `have_previous`), every reading finite, and the
/// device must not flag it. `fault_hint` follows the device flag's reason.
/// Every reason ends with ": zero duty sent" (the caller sends it).
std::optional<std::string> UnusableSample(const ActuatorSample& s, bool have_previous,
                                          int64_t previous_utime, const std::string& fault_hint);

/// The lowest leg the device's own guard holds at zero duty, or -1.
int DeviceGuardLeg(const ActuatorSample& s);

/// " at utime U": where a sample's message says when.
std::string AtUtime(int64_t utime);

}  // namespace stewart::identify::detail
