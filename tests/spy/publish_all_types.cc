// Publishes one message of every stewart type, on the channels of the
// config, `rounds` times every `period_ms` (for the lcm-spy test).
// `--channels` prints "CHANNEL TYPE" lines of what it publishes instead.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--channels") {
    const auto& c = stewart::LoadStackConfig(stewart::DefaultConfigPath()).lcm.channels;
    std::printf(
        "%s sensor_t\n%s state_t\n%s state_t\n%s setpoint_t\n%s force_command_t\n"
        "%s force_command_t\n%s safety_diagnostics_t\n%s health_t\n",
        c.sensors.c_str(), c.state_estimate.c_str(), c.state_truth.c_str(), c.setpoint.c_str(),
        c.command_nominal.c_str(), c.command_safe.c_str(), c.safety_diagnostics.c_str(),
        c.health.c_str());
    return 0;
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s LCM_URL [rounds=50] [period_ms=50]\n", argv[0]);
    return 2;
  }
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 50;
  const int period_ms = argc > 3 ? std::atoi(argv[3]) : 50;
  const stewart::StackConfig config = stewart::LoadStackConfig(stewart::DefaultConfigPath());
  const auto& ch = config.lcm.channels;
  auto lcm = stewart::MakeLcm(argv[1]);

  for (int k = 0; k < rounds; ++k) {
    const int64_t utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    stewart::sensor_t sensor{};
    sensor.utime = sensor.sample_utime = utime;
    sensor.seq = k;
    for (int i = 0; i < 6; ++i) sensor.leg_length_m[i] = 0.45 + 0.001 * i;
    sensor.accel_mps2[2] = 9.81;
    lcm->publish(ch.sensors, &sensor);

    stewart::state_t state{};
    state.utime = state.sample_utime = utime;
    state.seq = k;
    state.q[2] = 0.4;
    state.status = stewart::state_t::STATUS_VALID;
    lcm->publish(ch.state_estimate, &state);
    state.status |= stewart::state_t::STATUS_GROUND_TRUTH;
    lcm->publish(ch.state_truth, &state);

    stewart::setpoint_t setpoint{};
    setpoint.utime = setpoint.sample_utime = utime;
    setpoint.seq = k;
    setpoint.q_des[0] = 0.1;
    setpoint.q_des[2] = 0.4;
    lcm->publish(ch.setpoint, &setpoint);

    stewart::force_command_t command{};
    command.utime = command.sample_utime = utime;
    command.seq = k;
    for (int i = 0; i < 6; ++i) command.force_n[i] = 2.0 + 0.1 * i;
    lcm->publish(ch.command_nominal, &command);
    command.flags = stewart::force_command_t::FLAG_FILTER_ACTIVE;
    lcm->publish(ch.command_safe, &command);

    stewart::safety_diagnostics_t diag{};
    diag.utime = diag.sample_utime = utime;
    diag.seq = k;
    diag.num_position = 1;
    diag.position_names = {"x_upper"};
    diag.h_position = {1e-3};
    diag.alpha_h_position = {1e-3};
    diag.w_position = {1.0};
    diag.mu_position = {0.0};
    diag.num_velocity = 1;
    diag.velocity_names = {"xd_upper"};
    diag.h_velocity = {0.01};
    diag.alpha_h_velocity = {0.01};
    diag.w_velocity = {1.0};
    diag.mu_velocity = {0.0};
    diag.compute_ns = 1500;
    lcm->publish(ch.safety_diagnostics, &diag);

    stewart::health_t health{};
    health.utime = health.sample_utime = utime;
    health.seq = k;
    health.name = "publish_all_types";
    health.state = stewart::health_t::STATE_OK;
    health.num_counters = 1;
    health.counter_names = {"rounds"};
    health.counter_values = {k};
    health.counter_deltas = {1};
    health.worst_state = stewart::health_t::STATE_OK;
    lcm->publish(ch.health, &health);
    usleep(static_cast<useconds_t>(period_ms) * 1000);
  }
  return 0;
}
