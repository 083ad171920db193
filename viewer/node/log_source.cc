#include "log_source.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <set>

#include "message_samples.h"
#include "stewart/common/check.h"

namespace stewart::viewer {
namespace {

// Heartbeats share one channel: a process's newest is found among this
// many events before the instant (a few per process at 2 Hz each).
constexpr int kHealthLookback = 64;
// The history sent after a seek: enough points for a 10 s chart, few
// enough to decode at once.
constexpr double kHistoryRateHz = 25.0;

template <class Msg>
std::optional<Msg> Decode(const LcmLogIndex& index, const LcmLogIndex::Event* event) {
  if (event == nullptr) return std::nullopt;
  const std::vector<uint8_t> data = index.Payload(*event);
  Msg msg;
  if (msg.decode(data.data(), 0, static_cast<int>(data.size())) < 0) return std::nullopt;
  return msg;
}

template <class Msg>
std::optional<Msg> LatestAt(const LcmLogIndex& index, const std::string& channel, int64_t t_us) {
  return Decode<Msg>(index, index.LatestAtOrBefore(channel, t_us));
}

int64_t RangeStart(const LcmLogIndex& index, const std::string& channel) {
  const auto& events = index.EventsOf(channel);
  if (events.empty()) {
    throw InputError("--log", index.path() + " has no state estimate on " + channel);
  }
  return events.front().utime_us;
}

}  // namespace

LogSource::LogSource(const std::string& path, const StackConfig& config, const ViewerConfig& viewer,
                     const FrameBuilder* builder)
    : index_(path),
      channels_(config.lcm.channels),
      history_s_(viewer.history_s),
      builder_(builder),
      clock_(RangeStart(index_, channels_.state_estimate),
             index_.EventsOf(channels_.state_estimate).back().utime_us) {
  spdlog::info("viewer: {} indexed: {} events, stack time {:.3f} .. {:.3f} s{}", path,
               index_.total_events(), start_s(), end_s(),
               index_.truncated() ? " (cut short at its end: the complete events are kept)" : "");
}

void LogSource::NewViewer() {
  const std::lock_guard<std::mutex> lock(mutex_);
  history_due_ = true;
  changed_ = true;
}

void LogSource::Handle(const ClientMessage& message) {
  const auto now = PlaybackClock::Clock::now();
  const std::lock_guard<std::mutex> lock(mutex_);
  switch (message.kind) {
    case ClientMessage::Kind::kPlay:
      clock_.Play(now);
      break;
    case ClientMessage::Kind::kPause:
      clock_.Pause(now);
      break;
    case ClientMessage::Kind::kRate:
      clock_.SetRate(message.rate, now);
      break;
    case ClientMessage::Kind::kSeek:
      clock_.Seek(static_cast<int64_t>(std::llround(message.t_s * 1e6)), now);
      history_due_ = true;
      break;
    case ClientMessage::Kind::kOperator:
      throw InputError("command", "a recorded log cannot be commanded");
  }
  changed_ = true;
}

ViewerSnapshot LogSource::SnapshotAt(int64_t t_us) const {
  ViewerSnapshot s;
  if (auto m = LatestAt<state_t>(index_, channels_.state_estimate, t_us)) s.estimate = ToSample(*m);
  if (auto m = LatestAt<state_t>(index_, channels_.state_truth, t_us)) s.truth = ToSample(*m);
  if (auto m = LatestAt<setpoint_t>(index_, channels_.setpoint, t_us)) s.setpoint = ToSample(*m);
  if (auto m = LatestAt<force_command_t>(index_, channels_.command_nominal, t_us)) {
    s.nominal = ToSample(*m);
  }
  if (auto m = LatestAt<force_command_t>(index_, channels_.command_safe, t_us)) {
    s.safe = ToSample(*m);
  }
  if (auto m = LatestAt<safety_diagnostics_t>(index_, channels_.safety_diagnostics, t_us)) {
    s.diagnostics = ToSample(*m);
  }
  if (auto m = LatestAt<supervisor_state_t>(index_, channels_.supervisor, t_us)) {
    s.supervisor = ToSample(*m);
  }
  const auto& health = index_.EventsOf(channels_.health);
  const LcmLogIndex::Event* newest = index_.LatestAtOrBefore(channels_.health, t_us);
  if (newest != nullptr) {
    for (const LcmLogIndex::Event* e = newest; e >= health.data() && newest - e < kHealthLookback;
         --e) {
      if (auto m = Decode<health_t>(index_, e); m && s.health.count(m->name) == 0) {
        s.health[m->name] = ToSample(*m);
      }
    }
  }
  return s;
}

nlohmann::json LogSource::HistoryBefore(int64_t t_us) const {
  nlohmann::json t = nlohmann::json::array(), q = nlohmann::json::array(),
                 qd = nlohmann::json::array(), correction = nlohmann::json::array();
  const auto step_us = static_cast<int64_t>(1e6 / kHistoryRateHz);
  const int64_t from_us =
      std::max(clock_.start_us(), t_us - static_cast<int64_t>(history_s_ * 1e6));
  for (int64_t at = from_us; at <= t_us; at += step_us) {
    const auto state = LatestAt<state_t>(index_, channels_.state_estimate, at);
    if (!state) continue;
    const auto diag = LatestAt<safety_diagnostics_t>(index_, channels_.safety_diagnostics, at);
    t.push_back(static_cast<double>(state->utime) * 1e-6);
    q.push_back(std::vector<double>(std::begin(state->q), std::end(state->q)));
    qd.push_back(std::vector<double>(std::begin(state->qd), std::end(state->qd)));
    correction.push_back(diag ? diag->correction_norm : 0.0);
  }
  return {{"t_s", t}, {"q", q}, {"qd", qd}, {"correction_norm_n", correction}};
}

nlohmann::json LogSource::NextFrame() {
  int64_t t_us = 0;
  bool history = false;
  nlohmann::json playback;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    t_us = clock_.TimeAt(PlaybackClock::Clock::now());
    if (!changed_ && last_frame_utime_us_ == t_us) return nullptr;
    changed_ = false;
    last_frame_utime_us_ = t_us;
    history = history_due_;
    history_due_ = false;
    playback = {{"t_s", static_cast<double>(t_us) * 1e-6},
                {"playing", clock_.playing()},
                {"rate", clock_.rate()},
                {"start_s", start_s()},
                {"end_s", end_s()}};
  }
  nlohmann::json frame = builder_->Frame(SnapshotAt(t_us));
  frame["mode"] = "log";
  frame["playback"] = playback;
  if (history) frame["history"] = HistoryBefore(t_us);
  return frame;
}

}  // namespace stewart::viewer
