#pragma once
// Link quality and the device-to-host time mapping.
#include <array>
#include <cstdint>

namespace stewart::hw {

/// Maps the device clock (us) to the host time base (us) by passive
/// synchronisation (E. Olson, "A passive solution to the sensor
/// synchronization problem", IROS 2010): with d = device time and h = host
/// arrival time, every frame satisfies h - d >= offset (transport delay is
/// non-negative), so the offset estimate is the running minimum of h - d,
/// allowed to grow by the drift bound between frames:
///   offset_k = min(offset_{k-1} + drift * (d_k - d_{k-1}),  h_k - d_k)
///   utime_k  = d_k + offset_k
/// utime is then the host time at which the sample was taken, up to the
/// smallest transport delay seen, and is monotonic in d.
class DeviceClockMap {
 public:
  explicit DeviceClockMap(double drift_ppm) : drift_(drift_ppm * 1e-6) {}

  int64_t Map(uint64_t device_us, int64_t host_rx_us);
  int64_t offset_us() const { return static_cast<int64_t>(offset_us_); }
  /// Device clock went backwards (device reboot): mapping restarted.
  uint64_t resets() const { return resets_; }

 private:
  double drift_;
  bool initialised_ = false;
  uint64_t last_device_us_ = 0;
  double offset_us_ = 0.0;  // fractional: the drift allowance is < 1 us per frame
  uint64_t resets_ = 0;
};

/// Round-trip latency: the host remembers when it sent each command frame;
/// the device echoes the seq in force and how long it has held it, so
///   rtt = host_rx - host_tx(seq) - command_age
/// is the transport round trip without the device's hold time.
class RoundTripTracker {
 public:
  void OnSent(uint32_t seq, int64_t host_tx_us);
  /// Returns true and sets *rtt_us on the first echo of a remembered seq.
  bool OnEcho(uint32_t seq, uint32_t command_age_us, int64_t host_rx_us, int64_t* rtt_us);

 private:
  struct Entry {
    uint32_t seq = 0;
    int64_t tx_us = 0;
    bool valid = false;
  };
  std::array<Entry, 256> ring_{};
};

/// Running min / mean / max, reset per health window.
struct WindowStats {
  int64_t count = 0;
  double sum = 0.0;
  int64_t max = 0;
  int64_t last = 0;

  void Add(int64_t v) {
    if (count == 0 || v > max) max = v;
    ++count;
    sum += static_cast<double>(v);
    last = v;
  }
  int64_t mean() const { return count > 0 ? static_cast<int64_t>(sum / count) : 0; }
  void Reset() { *this = WindowStats{}; }
};

}  // namespace stewart::hw
