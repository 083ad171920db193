#include "stewart/hw_bridge/link_stats.h"

#include <algorithm>
#include <cmath>

namespace stewart::hw {

int64_t DeviceClockMap::Map(uint64_t device_us, int64_t host_rx_us) {
  const int64_t observed = host_rx_us - static_cast<int64_t>(device_us);
  if (initialised_ && device_us < last_device_us_) {
    ++resets_;
    initialised_ = false;
  }
  if (!initialised_) {
    offset_us_ = static_cast<double>(observed);
    initialised_ = true;
  } else {
    const double grown = offset_us_ + drift_ * static_cast<double>(device_us - last_device_us_);
    offset_us_ = std::min(grown, static_cast<double>(observed));
  }
  last_device_us_ = device_us;
  return static_cast<int64_t>(device_us) + static_cast<int64_t>(std::floor(offset_us_));
}

void RoundTripTracker::OnSent(uint32_t seq, int64_t host_tx_us) {
  ring_[seq % ring_.size()] = Entry{seq, host_tx_us, true};
}

bool RoundTripTracker::OnEcho(uint32_t seq, uint32_t command_age_us, int64_t host_rx_us,
                              int64_t* rtt_us) {
  Entry& e = ring_[seq % ring_.size()];
  if (!e.valid || e.seq != seq) return false;
  e.valid = false;
  *rtt_us = std::max<int64_t>(0, host_rx_us - e.tx_us - static_cast<int64_t>(command_age_us));
  return true;
}

}  // namespace stewart::hw
