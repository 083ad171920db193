#include "stewart/node/latency_histogram.h"

#include <algorithm>
#include <cmath>

namespace stewart {

void LatencyHistogram::Add(int64_t latency_us) {
  const int64_t clamped = std::clamp<int64_t>(latency_us, 0, kMaxUs + 1);
  ++bins_[static_cast<size_t>(clamped)];
  ++count_;
  max_us_ = std::max(max_us_, latency_us);
}

int64_t LatencyHistogram::Percentile(double p) const {
  if (count_ == 0) return 0;
  const auto needed = static_cast<int64_t>(std::ceil(p * static_cast<double>(count_)));
  int64_t seen = 0;
  for (size_t i = 0; i < bins_.size(); ++i) {
    seen += bins_[i];
    if (seen >= needed) return static_cast<int64_t>(i);
  }
  return kMaxUs + 1;
}

}  // namespace stewart
