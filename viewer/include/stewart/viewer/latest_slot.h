#pragma once
// A one-element mailbox that keeps only the newest item: what each browser's
// sender holds. An item offered before the previous one was taken replaces
// it and counts as dropped, so a slow reader costs items, never memory or
// the writer's time. Not synchronised: its owner holds the lock.
#include <cstdint>
#include <optional>
#include <utility>

namespace stewart::viewer {

template <class T>
class LatestSlot {
 public:
  /// Stores `item`; true when it replaced one that was never taken.
  bool Offer(T item) {
    const bool replaced = item_.has_value();
    if (replaced) ++dropped_;
    item_ = std::move(item);
    return replaced;
  }
  /// The newest item, emptying the slot; nullopt when empty.
  std::optional<T> Take() {
    std::optional<T> out = std::move(item_);
    item_.reset();
    return out;
  }
  bool empty() const { return !item_.has_value(); }
  int64_t dropped() const { return dropped_; }

 private:
  std::optional<T> item_;
  int64_t dropped_ = 0;
};

}  // namespace stewart::viewer
