#include "stewart/guard/leg_speed_estimator.h"

namespace stewart {

void LegSpeedEstimator::Add(int64_t utime, double length_m) {
  if (count_ > 0) {
    const int last = (next_ + kWindow - 1) % kWindow;
    const int64_t gap = utime - utime_[static_cast<std::size_t>(last)];
    if (gap <= 0 || gap > kMaxGapUs) count_ = 0;
  }
  utime_[static_cast<std::size_t>(next_)] = utime;
  length_m_[static_cast<std::size_t>(next_)] = length_m;
  next_ = (next_ + 1) % kWindow;
  if (count_ < kWindow) ++count_;
  // A full window only: over a few samples one ADC step of a leg at rest
  // reads as a speed (0.2 mm in 4 ms is 50 mm/s).
  if (count_ < kWindow) {
    speed_mps_ = 0.0;
    return;
  }
  // Slope of length over time, both relative to the newest reading (keeps
  // the sums small and exact enough in double).
  const int newest = (next_ + kWindow - 1) % kWindow;
  const int64_t t0 = utime_[static_cast<std::size_t>(newest)];
  const double l0 = length_m_[static_cast<std::size_t>(newest)];
  double st = 0.0, sl = 0.0, stt = 0.0, stl = 0.0;
  for (int k = 0; k < count_; ++k) {
    const auto j = static_cast<std::size_t>((newest + kWindow - k) % kWindow);
    const double t = static_cast<double>(utime_[j] - t0) * 1e-6;
    const double l = length_m_[j] - l0;
    st += t;
    sl += l;
    stt += t * t;
    stl += t * l;
  }
  const double n = count_;
  const double denominator = n * stt - st * st;
  speed_mps_ = denominator > 0.0 ? (n * stl - st * sl) / denominator : 0.0;
}

}  // namespace stewart
