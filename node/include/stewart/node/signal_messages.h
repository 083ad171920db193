#pragma once
// Conversions between the LCM messages and the libraries' signals
// (common/signals.h), at the edge of every node and of replay.
#include "stewart/common/signals.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/eigen_msg.h"
#include "stewart/state_t.hpp"

namespace stewart {

static_assert(kStateValid == state_t::STATUS_VALID &&
                  kStateInitializing == state_t::STATUS_INITIALIZING &&
                  kStateDiverged == state_t::STATUS_DIVERGED &&
                  kStateGroundTruth == state_t::STATUS_GROUND_TRUTH &&
                  kStatePerfectState == state_t::STATUS_PERFECT_STATE,
              "signals.h and state_t.STATUS_* must agree");
static_assert(kCommandFilterActive == force_command_t::FLAG_FILTER_ACTIVE &&
                  kCommandInfeasible == force_command_t::FLAG_INFEASIBLE &&
                  kCommandFallback == force_command_t::FLAG_FALLBACK &&
                  kCommandStaleInput == force_command_t::FLAG_STALE_INPUT &&
                  kCommandInvalidInput == force_command_t::FLAG_INVALID_INPUT &&
                  kCommandSetpointRejected == force_command_t::FLAG_SETPOINT_REJECTED &&
                  kCommandForceLimited == force_command_t::FLAG_FORCE_LIMITED,
              "signals.h and force_command_t.FLAG_* must agree");

inline StateSample FromMessage(const state_t& msg) {
  StateSample s;
  s.utime = msg.utime;
  s.seq = msg.seq;
  s.sample_utime = msg.sample_utime;
  s.q = FromArray(msg.q);
  s.qd = FromArray(msg.qd);
  s.q_std = FromArray(msg.q_std);
  s.qd_std = FromArray(msg.qd_std);
  s.status = msg.status;
  return s;
}

inline void ToMessage(const StateSample& s, state_t* msg) {
  msg->utime = s.utime;
  msg->seq = s.seq;
  msg->sample_utime = s.sample_utime;
  ToArray(s.q, msg->q);
  ToArray(s.qd, msg->qd);
  ToArray(s.q_std, msg->q_std);
  ToArray(s.qd_std, msg->qd_std);
  msg->status = s.status;
}

inline ForceCommand FromMessage(const force_command_t& msg) {
  ForceCommand c;
  c.utime = msg.utime;
  c.seq = msg.seq;
  c.sample_utime = msg.sample_utime;
  c.force_n = FromArray(msg.force_n);
  c.flags = msg.flags;
  return c;
}

inline void ToMessage(const ForceCommand& c, force_command_t* msg) {
  msg->utime = c.utime;
  msg->seq = c.seq;
  msg->sample_utime = c.sample_utime;
  ToArray(c.force_n, msg->force_n);
  msg->flags = c.flags;
}

}  // namespace stewart
