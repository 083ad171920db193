#pragma once
// The fit's samples from a recorded run (an LCM log of tools/launch.sh): each
// usable state paired with the safe command that answered it.
#include <string>
#include <vector>

#include "stewart/identify/identification_sample.h"

namespace stewart::identify {

struct LogSamples {
  std::vector<IdentificationSample> samples;  ///< in sample time order
  long states = 0;                            ///< state_t messages on the state channel
  long unusable_states = 0;                   ///< of those: not valid, diverged or initialising
  long commands = 0;                          ///< force_command_t messages on the command channel
  long unanswered_states = 0;                 ///< usable states no command answered (not recorded)
  /// Usable states answered with the actuators off: the legs were held by
  /// their lead screws, so the commanded zero is not the force that acted.
  long drive_off_states = 0;
};

/// Reads `log_path`: state_t on `state_channel` (the estimate, or the ground
/// truth in simulation), force_command_t on `command_channel` (CMD_SAFE),
/// paired by sample_utime; the first command for a sample is the one the
/// plant applied. Throws IdentificationError when the log cannot be read or a
/// channel has no decodable message (naming it).
LogSamples ReadLogSamples(const std::string& log_path, const std::string& state_channel,
                          const std::string& command_channel);

}  // namespace stewart::identify
