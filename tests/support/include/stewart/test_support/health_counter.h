#pragma once
// A heartbeat's named counter, for tests that read what a process counted.
#include <cstddef>
#include <cstdint>
#include <string>

#include "stewart/health_t.hpp"

namespace stewart::test {

/// The value of counter `name` in `health`; 0 when the heartbeat has none.
inline int64_t HealthCounter(const health_t& health, const std::string& name) {
  for (int i = 0; i < health.num_counters; ++i) {
    if (health.counter_names[static_cast<size_t>(i)] == name) {
      return health.counter_values[static_cast<size_t>(i)];
    }
  }
  return 0;
}

}  // namespace stewart::test
