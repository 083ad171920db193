#include "sample_checks.h"

#include <cmath>

namespace stewart::identify::detail {

std::string AtUtime(int64_t utime) { return " at utime " + std::to_string(utime); }

std::optional<std::string> UnusableSample(const ActuatorSample& s, bool have_previous,
                                          int64_t previous_utime, const std::string& fault_hint) {
  const std::string at = AtUtime(s.utime);
  if (have_previous && s.utime <= previous_utime) {
    return "the device's sample time went backwards" + at + " (previous " +
           std::to_string(previous_utime) + "): zero duty sent";
  }
  for (int i = 0; i < kNumLegs; ++i) {
    if (!std::isfinite(s.leg_length_m(i))) {
      return "non-finite reading of leg " + std::to_string(i) + at + ": zero duty sent";
    }
  }
  if (!s.valid) {
    return "the device flags the sample" + at + " (a leg or pot fault" + fault_hint +
           "): zero duty sent";
  }
  return std::nullopt;
}

int DeviceGuardLeg(const ActuatorSample& s) {
  for (int i = 0; i < kNumLegs; ++i) {
    if ((s.device_guard_mask >> i) & 1U) return i;
  }
  return -1;
}

}  // namespace stewart::identify::detail
