#pragma once
// Which operator commands (operator_command_t on OPERATOR) an actuator
// believes: only RESET concerns it (clearing its guard's latch), and a RESET
// moves the platform again, so it must be authentic (MAC), recent by the
// receiver's wall clock (supervisor.operator_time_window_s either way: the operator's
// console stamps its wall clock) and newer than the last one of the same
// console (seq per operator_id), so a replayed log clears nothing.
// No LCM, no allocation: a fixed table of the last consoles seen.
#include <array>
#include <cstdint>

#include "stewart/common/enum_table.h"

namespace stewart {

enum class OperatorVerdict : uint8_t {
  kAccepted,
  kUnauthentic,       ///< the MAC does not verify
  kZeroOperator,      ///< operator_id 0 is never a console
  kStale,             ///< its utime is too far from the receiver's wall clock
  kSeqNotIncreasing,  ///< not newer than that console's last (a replay)
};
inline constexpr EnumTable<OperatorVerdict, 5> kOperatorVerdictNames{{{
    {OperatorVerdict::kAccepted, "accepted"},
    {OperatorVerdict::kUnauthentic, "operator_unauthentic"},
    {OperatorVerdict::kZeroOperator, "operator_zero_id"},
    {OperatorVerdict::kStale, "operator_stale"},
    {OperatorVerdict::kSeqNotIncreasing, "operator_seq_not_increasing"},
}}};
inline const char* ToString(OperatorVerdict v) { return kOperatorVerdictNames.Name(v).data(); }

class OperatorCommandCheck {
 public:
  static constexpr int kConsoles = 8;

  /// max_age_us > 0 (checked).
  explicit OperatorCommandCheck(int64_t max_age_us);

  /// `utime`: the command's (operator's wall clock, us); `wall_now_us`: the
  /// receiver's wall clock (us since the epoch).
  OperatorVerdict Check(int64_t operator_id, int64_t seq, int64_t utime, bool authentic,
                        int64_t wall_now_us);

 private:
  struct Console {
    int64_t operator_id = 0;
    int64_t seq = 0;
    int64_t used = 0;  // the check count when last accepted: evict the oldest
  };
  int64_t max_age_us_;
  std::array<Console, kConsoles> consoles_{};
  int64_t checks_ = 0;
};

}  // namespace stewart
