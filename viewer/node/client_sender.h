#pragma once
// One browser's sender: its own thread writes to its WebSocket, so a slow
// browser blocks only itself. It holds at most one frame, the newest: a
// frame offered while the previous one is still unsent replaces it (counted
// as dropped). Control replies (hello, errors) queue and are never dropped.
#include <civetweb.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "stewart/viewer/frame_rate_limiter.h"
#include "stewart/viewer/latest_slot.h"

namespace stewart::viewer {

class ClientSender {
 public:
  ClientSender(mg_connection* connection, double max_frame_rate_hz);
  /// Stops and joins the thread (a write in progress ends with its timeout).
  ~ClientSender();
  ClientSender(const ClientSender&) = delete;
  ClientSender& operator=(const ClientSender&) = delete;

  void OfferFrame(std::shared_ptr<const std::string> frame);
  void SendControl(std::string message);
  int64_t frames_sent() const;
  int64_t frames_dropped() const;

 private:
  void Run();

  mg_connection* const connection_;
  FrameRateLimiter limiter_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  LatestSlot<std::shared_ptr<const std::string>> pending_frame_;
  std::deque<std::string> pending_control_;
  bool stop_ = false;
  int64_t frames_sent_ = 0;
  std::thread thread_;  ///< last: starts once the members above exist
};

}  // namespace stewart::viewer
