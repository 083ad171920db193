#include "stewart/config/sections.h"

namespace stewart {
LcmConfig ParseLcmConfig(const ConfigNode& lcm, const ConfigNode& rates) {
  LcmConfig c;
  c.url = lcm.String("url");
  c.channel_prefix = lcm.String("channel_prefix");
  c.channel_suffix = lcm.Has("channel_suffix") ? lcm.String("channel_suffix") : "";
  const ConfigNode channels = lcm.Child("channels");
  for (const ChannelField& field : kChannelFields) {
    const std::string base = channels.String(field.key);
    if (base.empty()) channels.Fail(field.key, "channel name must not be empty");
    c.channels.*field.member = base;
  }
  // Store bare names, then apply prefix and suffix in one place.
  const std::string suffix = c.channel_suffix;
  c.channel_suffix.clear();
  for (const ChannelField& field : kChannelFields) {
    c.channels.*field.member = c.channel_prefix + c.channels.*field.member;
  }
  SetChannelSuffix(&c, suffix);
  c.health_rate_hz = rates.PositiveDouble("health_hz");
  c.auth_key_file = lcm.Has("auth_key_file") ? lcm.String("auth_key_file") : "";
  // Optional, so the configs of runs recorded before them still load.
  if (lcm.Has("time_window_s")) c.time_plausibility.window_s = lcm.PositiveDouble("time_window_s");
  if (lcm.Has("max_time_rate")) {
    c.time_plausibility.max_rate = lcm.PositiveDouble("max_time_rate");
    if (c.time_plausibility.max_rate < 1.0) {
      lcm.Fail("max_time_rate", "must be >= 1 (stack time runs at least at the wall rate)");
    }
  }
  return c;
}

}  // namespace stewart
