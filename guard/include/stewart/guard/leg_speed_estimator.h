#pragma once
// A leg's speed from its length readings (the pots), for the guards that
// watch the legs on the actuators' own readings: the last-line guard
// (actuator_guard.h) and bring-up's leg guard (hw_bridge/leg_guard.h).
#include <array>
#include <cstdint>

namespace stewart {

/// Leg speed from the last kWindow readings by a least-squares slope (a
/// 25 ms window at 1 kHz: the pot's quantisation, 0.2 mm on the simulated
/// 10-bit ADC, gives ~3 mm/s of noise on it, against 0.2 m/s on a one-sample
/// difference, at 12 ms of delay). Fixed size, no allocation.
class LegSpeedEstimator {
 public:
  static constexpr int kWindow = 25;
  /// Readings further apart than this restart the window.
  static constexpr int64_t kMaxGapUs = 100'000;

  void Add(int64_t utime, double length_m);
  /// 0 until the window is full (after a start or a gap).
  double speed_mps() const { return speed_mps_; }
  /// The window is full: speed_mps() is an estimate, not the 0 of a start.
  bool valid() const { return count_ == kWindow; }
  void Reset() { count_ = 0, speed_mps_ = 0.0; }

 private:
  std::array<int64_t, kWindow> utime_{};
  std::array<double, kWindow> length_m_{};
  int next_ = 0;
  int count_ = 0;
  double speed_mps_ = 0.0;
};

}  // namespace stewart
