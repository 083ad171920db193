#pragma once
// A recorded run played into the same page: the log is indexed once at
// start (LcmLogIndex), and each frame is the newest message of every channel
// at the playback clock's stack time, so a seek shows any instant at once.
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/viewer/client_message.h"
#include "stewart/viewer/frame_builder.h"
#include "stewart/viewer/lcm_log_index.h"
#include "stewart/viewer/playback_clock.h"
#include "stewart/viewer/viewer_config.h"

namespace stewart::viewer {

class LogSource {
 public:
  /// Throws InputError for a log that cannot be read or has no state estimate.
  LogSource(const std::string& path, const StackConfig& config, const ViewerConfig& viewer,
            const FrameBuilder* builder);

  /// The frame at the playback clock's time; null when paused and unchanged.
  nlohmann::json NextFrame();
  /// Play, pause, rate and seek; an operator command is refused (a log).
  void Handle(const ClientMessage& message);
  /// A browser connected: the next frame carries the charts' history.
  void NewViewer();

  double start_s() const { return static_cast<double>(clock_.start_us()) * 1e-6; }
  double end_s() const { return static_cast<double>(clock_.end_us()) * 1e-6; }

 private:
  ViewerSnapshot SnapshotAt(int64_t utime_us) const;
  /// The strip charts' samples over the history before utime_us.
  nlohmann::json HistoryBefore(int64_t utime_us) const;

  LcmLogIndex index_;
  ChannelNames channels_;
  double history_s_;
  const FrameBuilder* builder_;
  std::mutex mutex_;  ///< the clock: browsers' threads control it, the publisher reads it
  PlaybackClock clock_;
  bool changed_ = true;      ///< a control since the previous frame
  bool history_due_ = true;  ///< a seek or a new browser: send the charts' history
  std::optional<int64_t> last_frame_utime_us_;
};

}  // namespace stewart::viewer
