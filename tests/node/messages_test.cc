// The message contract: every type round-trips through LCM encoding, starts
// with utime, and carries seq and sample_utime.
#include <gtest/gtest.h>

#include <vector>

#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/lcm_messages.h"

namespace stewart {
namespace {

template <typename Msg>
Msg RoundTrip(const Msg& in) {
  std::vector<uint8_t> buffer(static_cast<size_t>(in.getEncodedSize()));
  EXPECT_EQ(in.encode(buffer.data(), 0, static_cast<int>(buffer.size())),
            static_cast<int>(buffer.size()));
  Msg out;
  EXPECT_EQ(out.decode(buffer.data(), 0, static_cast<int>(buffer.size())),
            static_cast<int>(buffer.size()));
  // utime is the first field: it sits right after the 8-byte type hash.
  int64_t utime_big_endian = 0;
  for (int i = 0; i < 8; ++i)
    utime_big_endian = (utime_big_endian << 8) | buffer[8 + static_cast<size_t>(i)];
  EXPECT_EQ(utime_big_endian, in.utime);
  return out;
}

TEST(Messages, SensorRoundTrip) {
  sensor_t m{};
  m.utime = 1234567;
  m.seq = 7;
  m.sample_utime = 1234567;
  for (int i = 0; i < 6; ++i) m.leg_length_m[i] = 0.4 + 0.01 * i;
  m.gyro_radps[2] = 0.25;
  m.accel_mps2[2] = 9.81;
  m.status = sensor_t::STATUS_ENDSTOP;
  const sensor_t out = RoundTrip(m);
  EXPECT_EQ(out.seq, 7);
  EXPECT_EQ(out.sample_utime, m.sample_utime);
  EXPECT_DOUBLE_EQ(out.leg_length_m[5], 0.45);
  EXPECT_DOUBLE_EQ(out.accel_mps2[2], 9.81);
  EXPECT_EQ(out.status, +sensor_t::STATUS_ENDSTOP);
}

TEST(Messages, StateSetpointCommandRoundTrip) {
  state_t s{};
  s.utime = 42;
  s.seq = 3;
  s.sample_utime = 41;
  s.q[2] = 0.4;
  s.qd_std[5] = 1e-3;
  s.status = state_t::STATUS_VALID;
  const state_t s2 = RoundTrip(s);
  EXPECT_EQ(s2.sample_utime, 41);
  EXPECT_DOUBLE_EQ(s2.q[2], 0.4);
  EXPECT_DOUBLE_EQ(s2.qd_std[5], 1e-3);

  setpoint_t p{};
  p.utime = 5;
  p.q_des[0] = 0.1;
  EXPECT_DOUBLE_EQ(RoundTrip(p).q_des[0], 0.1);

  force_command_t f{};
  f.utime = 9;
  f.sample_utime = 9;
  f.force_n[3] = -12.5;
  f.flags = force_command_t::FLAG_FILTER_ACTIVE | force_command_t::FLAG_FALLBACK;
  const force_command_t f2 = RoundTrip(f);
  EXPECT_DOUBLE_EQ(f2.force_n[3], -12.5);
  EXPECT_EQ(f2.flags, f.flags);
}

TEST(Messages, VariableLengthDiagnosticsAndHealth) {
  safety_diagnostics_t d{};
  d.utime = 100;
  test::SetGroups({{"x_upper", "leg3_max"}, {1e-3, 2e-3}, {1e-3, 4e-3}, {0.75, 0.25}, {0.0, 0.0}},
                  {{"zd_upper"}, {0.01}, {0.02}, {1.0}, {0.0}}, &d);
  d.active_case = safety_diagnostics_t::CASE_BOTH;
  d.compute_ns = 250;
  const safety_diagnostics_t d2 = RoundTrip(d);
  EXPECT_EQ(d2.position_names[1], "leg3_max");
  EXPECT_DOUBLE_EQ(d2.w_position[0], 0.75);
  EXPECT_EQ(d2.active_case, +safety_diagnostics_t::CASE_BOTH);

  health_t h{};
  h.utime = 77;
  h.name = "estimator";
  h.num_counters = 1;
  h.counter_names = {"rejected_nan"};
  h.counter_values = {3};
  h.counter_deltas = {2};
  h.worst_state = health_t::STATE_FAULT;
  h.fault_latched = true;
  h.latched_error = "every state rejected";
  h.rejected_inputs_delta = 5;
  const health_t h2 = RoundTrip(h);
  EXPECT_EQ(h2.name, "estimator");
  EXPECT_EQ(h2.counter_values[0], 3);
  EXPECT_EQ(h2.counter_deltas[0], 2);
  EXPECT_EQ(h2.worst_state, +health_t::STATE_FAULT);
  EXPECT_TRUE(h2.fault_latched);
  EXPECT_EQ(h2.latched_error, "every state rejected");
  EXPECT_EQ(h2.rejected_inputs_delta, 5);
}

}  // namespace
}  // namespace stewart
