#include "stewart/guard/operator_command_check.h"

#include "stewart/common/check.h"

namespace stewart {

OperatorCommandCheck::OperatorCommandCheck(int64_t max_age_us) : max_age_us_(max_age_us) {
  STEWART_CHECK(max_age_us > 0, "OperatorCommandCheck: max_age_us must be positive");
}

OperatorVerdict OperatorCommandCheck::Check(int64_t operator_id, int64_t seq, int64_t utime,
                                            bool authentic, int64_t wall_now_us) {
  ++checks_;
  if (!authentic) return OperatorVerdict::kUnauthentic;
  if (operator_id == 0) return OperatorVerdict::kZeroOperator;
  const int64_t skew_us = wall_now_us - utime;
  if (skew_us > max_age_us_ || skew_us < -max_age_us_) return OperatorVerdict::kStale;
  Console* slot = nullptr;
  Console* oldest = &consoles_[0];
  for (Console& c : consoles_) {
    if (c.operator_id == operator_id) slot = &c;
    if (c.used < oldest->used) oldest = &c;
  }
  if (slot != nullptr && seq <= slot->seq) return OperatorVerdict::kSeqNotIncreasing;
  // A console evicted from the table could be replayed within max_age: it
  // takes more than kConsoles consoles within that time, which is not an
  // accident, and a host that can do it on purpose has the key anyway.
  if (slot == nullptr) slot = oldest;
  *slot = Console{operator_id, seq, checks_};
  return OperatorVerdict::kAccepted;
}

}  // namespace stewart
