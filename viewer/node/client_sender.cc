#include "client_sender.h"

#include <spdlog/spdlog.h>

namespace stewart::viewer {

ClientSender::ClientSender(mg_connection* connection, double max_frame_rate_hz)
    : connection_(connection), limiter_(max_frame_rate_hz), thread_([this] { Run(); }) {}

ClientSender::~ClientSender() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void ClientSender::OfferFrame(std::shared_ptr<const std::string> frame) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    pending_frame_.Offer(std::move(frame));
  }
  wake_.notify_all();
}

void ClientSender::SendControl(std::string message) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    pending_control_.push_back(std::move(message));
  }
  wake_.notify_all();
}

int64_t ClientSender::frames_sent() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return frames_sent_;
}

int64_t ClientSender::frames_dropped() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return pending_frame_.dropped();
}

void ClientSender::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    std::string control;
    std::shared_ptr<const std::string> frame;
    if (!pending_control_.empty()) {
      control = std::move(pending_control_.front());
      pending_control_.pop_front();
    } else if (!pending_frame_.empty()) {
      if (!limiter_.TryTake(FrameRateLimiter::Clock::now())) {
        wake_.wait_until(lock, limiter_.NextAllowed());
        continue;
      }
      frame = *pending_frame_.Take();
    } else {
      wake_.wait(lock);
      continue;
    }
    // Written without the lock: new frames keep replacing the pending one
    // meanwhile, which is how a slow browser drops frames.
    lock.unlock();
    const std::string& text = frame != nullptr ? *frame : control;
    const int written =
        mg_websocket_write(connection_, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size());
    lock.lock();
    if (written <= 0) {
      // The browser went away; civetweb closes the connection and its close
      // handler destroys this sender.
      spdlog::debug("viewer: a browser's WebSocket write failed; it stops receiving");
      stop_ = true;
      break;
    }
    if (frame != nullptr) ++frames_sent_;
  }
}

}  // namespace stewart::viewer
