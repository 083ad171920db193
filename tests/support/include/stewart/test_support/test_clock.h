#pragma once
// Times the tests of the receive-time checks share (us).
#include <cstdint>

namespace stewart::test {

/// A wall clock in 2026, us since the epoch: "now" for the time checks.
inline constexpr int64_t kWallUs = 1'780'000'000'000'000;
/// One millisecond, in us.
inline constexpr int64_t kMsUs = 1000;

}  // namespace stewart::test
