#pragma once
// Wall-clock latencies of one process's loop (e.g. plant_sim: sensor sample
// published -> safe command for it received), with percentiles, in fixed
// storage: 1 us bins up to kMaxUs, everything above in one overflow bin.
#include <array>
#include <cstdint>

namespace stewart {

class LatencyHistogram {
 public:
  static constexpr int64_t kMaxUs = 20000;

  void Add(int64_t latency_us);
  int64_t count() const { return count_; }
  int64_t max_us() const { return max_us_; }
  /// The smallest latency (us) that at least fraction p of the samples do
  /// not exceed, p in (0, 1]; kMaxUs + 1 when that is in the overflow bin;
  /// 0 when empty.
  int64_t Percentile(double p) const;

 private:
  std::array<int64_t, kMaxUs + 2> bins_{};
  int64_t count_ = 0;
  int64_t max_us_ = 0;
};

}  // namespace stewart
