#pragma once
// One message lost on its way, on purpose (testing only): a node told to lose
// its output numbered `seq` does not publish it the first time, as if the
// network had dropped that datagram (UDP drops silently, e.g. when a
// receiver's queue overflows). Everything else is as after sending it: the
// node's state has moved on, a later copy of that output (an answer to a
// resend, common/resend_answer.h) goes out. tests/stack/lockstep_resend_test.cc.
#include <spdlog/spdlog.h>

#include <cstdint>
#include <optional>
#include <string>

namespace stewart {

class TestLoss {
 public:
  /// Loses the first output numbered `seq` published on `channel`.
  void Lose(std::string channel, int64_t seq) {
    channel_ = std::move(channel);
    seq_ = seq;
  }
  /// Whether the output `seq` on `channel` is to be lost (once).
  bool Drops(const std::string& channel, int64_t seq) {
    if (!seq_ || *seq_ != seq || channel != channel_) return false;
    seq_.reset();
    spdlog::warn("TEST: output {} on {} lost on purpose (--test-lose-seq)", seq, channel);
    return true;
  }

 private:
  std::string channel_;
  std::optional<int64_t> seq_;
};

}  // namespace stewart
