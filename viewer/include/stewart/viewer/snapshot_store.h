#pragma once
// The hand-over between the thread that receives (LCM) and the thread that
// serves: the receiver only overwrites the newest values under a short lock,
// never waits for a browser; the server copies them when it builds a frame.
#include <cstdint>
#include <mutex>

#include "stewart/viewer/snapshot.h"

namespace stewart::viewer {

class SnapshotStore {
 public:
  /// Applies `update` to the stored snapshot under the lock.
  template <class Fn>
  void Update(Fn&& update) {
    const std::lock_guard<std::mutex> lock(mutex_);
    update(snapshot_);
    ++version_;
  }
  /// A copy of the newest values and their version (increments per update).
  ViewerSnapshot Copy(uint64_t* version = nullptr) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (version != nullptr) *version = version_;
    return snapshot_;
  }

 private:
  mutable std::mutex mutex_;
  ViewerSnapshot snapshot_;
  uint64_t version_ = 0;
};

}  // namespace stewart::viewer
