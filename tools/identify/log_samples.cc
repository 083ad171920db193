#include "log_samples.h"

#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <map>

#include "stewart/common/signals.h"
#include "stewart/force_command_t.hpp"
#include "stewart/identify/inertial_fit.h"
#include "stewart/state_t.hpp"

namespace stewart::identify {
namespace {

Vector6d Vector6Of(const double (&v)[6]) { return Eigen::Map<const Vector6d>(v); }

}  // namespace

LogSamples ReadLogSamples(const std::string& log_path, const std::string& state_channel,
                          const std::string& command_channel) {
  if (!std::filesystem::is_regular_file(log_path)) {
    throw IdentificationError("no log file '" + log_path + "'");
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw IdentificationError("cannot read the LCM log '" + log_path + "'");
  LogSamples out;
  std::map<std::int64_t, state_t> states;            // by sample_utime
  std::map<std::int64_t, force_command_t> commands;  // the first for each sample_utime
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel == state_channel) {
      state_t s;
      if (s.decode(e->data, 0, e->datalen) < 0) continue;
      ++out.states;
      if (!StateUsable(s.status) || (s.status & kStateInitializing) != 0) {
        ++out.unusable_states;
        continue;
      }
      states.emplace(s.sample_utime, s);
    } else if (e->channel == command_channel) {
      force_command_t c;
      if (c.decode(e->data, 0, e->datalen) < 0) continue;
      ++out.commands;
      commands.emplace(c.sample_utime, c);
    }
  }
  if (out.states == 0) {
    throw IdentificationError("no state_t message on '" + state_channel + "' in '" + log_path +
                              "'");
  }
  if (out.commands == 0) {
    throw IdentificationError("no force_command_t message on '" + command_channel + "' in '" +
                              log_path + "'");
  }
  for (const auto& [sample_utime, s] : states) {
    const auto c = commands.find(sample_utime);
    if (c == commands.end()) {
      ++out.unanswered_states;
      continue;
    }
    if ((c->second.flags & force_command_t::FLAG_DRIVE_OFF) != 0) {
      ++out.drive_off_states;
      continue;
    }
    IdentificationSample sample;
    sample.utime = sample_utime;
    sample.q = Vector6Of(s.q);
    sample.qd = Vector6Of(s.qd);
    sample.force_n = Vector6Of(c->second.force_n);
    out.samples.push_back(sample);
  }
  return out;
}

}  // namespace stewart::identify
