#pragma once
// Conversions between the LCM messages and the libraries' signals
// (common/signals.h), at the edge of every node and of replay.
#include <tuple>

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
                  kCommandForceLimited == force_command_t::FLAG_FORCE_LIMITED &&
                  kCommandOutsideSafeSet == force_command_t::FLAG_OUTSIDE_SAFE_SET &&
                  kCommandDriveOff == force_command_t::FLAG_DRIVE_OFF &&
                  kCommandNominalBounded == force_command_t::FLAG_NOMINAL_BOUNDED &&
                  kCommandPerBarrier == force_command_t::FLAG_PER_BARRIER,
              "signals.h and force_command_t.FLAG_* must agree");

/// For each message, the library signal it carries and the fields both share
/// (by the same names), in one list for both directions.
template <typename Msg>
struct SignalOf;

template <>
struct SignalOf<state_t> {
  using Type = StateSample;
  template <typename State>
  static auto Fields(State& s) {
    return std::tie(s.utime, s.seq, s.sample_utime, s.q, s.qd, s.q_std, s.qd_std, s.disturbance,
                    s.disturbance_std, s.status);
  }
};

template <>
struct SignalOf<force_command_t> {
  using Type = ForceCommand;
  template <typename Command>
  static auto Fields(Command& c) {
    return std::tie(c.utime, c.seq, c.sample_utime, c.force_n, c.flags, c.session_id);
  }
};

/// state_t -> StateSample, force_command_t -> ForceCommand.
template <typename Msg>
typename SignalOf<Msg>::Type FromMessage(const Msg& msg) {
  typename SignalOf<Msg>::Type signal;
  CopyFields(SignalOf<Msg>::Fields(msg), SignalOf<Msg>::Fields(signal));
  return signal;
}

/// StateSample -> state_t, ForceCommand -> force_command_t.
template <typename Msg>
void ToMessage(const typename SignalOf<Msg>::Type& signal, Msg* msg) {
  CopyFields(SignalOf<Msg>::Fields(signal), SignalOf<Msg>::Fields(*msg));
}

}  // namespace stewart
