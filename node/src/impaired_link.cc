#include "stewart/node/impaired_link.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace stewart {

void ValidateLinkImpairment(const LinkImpairment& impairment) {
  const auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(what);
  };
  check(std::isfinite(impairment.delay_ms) && impairment.delay_ms >= 0.0 &&
            impairment.delay_ms <= 60000.0,
        "delay_ms must be within 0..60000 ms");
  check(std::isfinite(impairment.jitter_ms) && impairment.jitter_ms >= 0.0 &&
            impairment.jitter_ms <= 60000.0,
        "jitter_ms must be within 0..60000 ms");
  check(std::isfinite(impairment.loss) && impairment.loss >= 0.0 && impairment.loss <= 1.0,
        "loss must be a probability within 0..1");
}

ImpairedLink::ImpairedLink(const LinkImpairment& impairment, uint32_t seed, size_t max_datagrams,
                           size_t max_bytes)
    : impairment_(impairment), rng_(seed), max_datagrams_(max_datagrams), max_bytes_(max_bytes) {
  ValidateLinkImpairment(impairment_);
}

void ImpairedLink::Offer(const uint8_t* data, size_t size, int64_t now_us) {
  ++counters_.offered;
  // Both draws are made for every datagram, so the same seed gives the same
  // fate to the n-th datagram whatever the settings.
  const double loss_draw = unit_(rng_);
  const double jitter_draw = unit_(rng_);
  if (loss_draw < impairment_.loss) {
    ++counters_.lost;
    return;
  }
  if (queue_.size() >= max_datagrams_ || queued_bytes_ + size > max_bytes_) {
    ++counters_.overflow;
    return;
  }
  const double delay_us = 1000.0 * (impairment_.delay_ms + jitter_draw * impairment_.jitter_ms);
  queue_.push({now_us + static_cast<int64_t>(std::llround(delay_us)), next_order_++,
               std::vector<uint8_t>(data, data + size)});
  queued_bytes_ += size;
  counters_.max_queued =
      std::max<int64_t>(counters_.max_queued, static_cast<int64_t>(queue_.size()));
}

std::optional<int64_t> ImpairedLink::NextDueUs() const {
  if (queue_.empty()) return std::nullopt;
  return queue_.top().due_us;
}

}  // namespace stewart
