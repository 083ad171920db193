#pragma once
// Which command frames the device accepts (docs/wire-protocol.md,
// "Sessions"): those of the link session it follows, newer than the last
// accepted one (seq modulo 2^32), and a new session's first frame only when
// the device is not driven by another (none yet, or its watchdog expired),
// the session is not one the device followed before, and the frame asks for
// no motion. What a real device's firmware does; the emulator runs it.
#include <array>
#include <cstddef>
#include <cstdint>

#include "stewart/common/enum_table.h"
#include "stewart/hw_bridge/wire_format.h"

namespace stewart::hw {

enum class CommandAcceptance {
  kApplied,         ///< the session's next frame: in force from its arrival
  kAdopted,         ///< a new session starts with this frame; its seq check restarts here
  kNotNewer,        ///< the session's duplicate or reordered frame: dropped
  kRetiredSession,  ///< a session the device followed before (an old bridge's late frame)
  kSessionLive,     ///< another session while the current one still drives the legs
  kNeedsNoMotion,   ///< a new session's frame that asks for motion
};
inline constexpr EnumTable<CommandAcceptance, 6> kCommandAcceptanceNames{{{
    {CommandAcceptance::kApplied, "applied"},
    {CommandAcceptance::kAdopted, "adopted"},
    {CommandAcceptance::kNotNewer, "not_newer"},
    {CommandAcceptance::kRetiredSession, "retired_session"},
    {CommandAcceptance::kSessionLive, "session_live"},
    {CommandAcceptance::kNeedsNoMotion, "needs_no_motion"},
}}};
inline const char* ToString(CommandAcceptance a) { return kCommandAcceptanceNames.Name(a).data(); }

/// The frame is put in force (kApplied, kAdopted).
inline bool Applies(CommandAcceptance a) {
  return a == CommandAcceptance::kApplied || a == CommandAcceptance::kAdopted;
}
/// Counted in the sensor frame's rx_session_rejected.
bool IsSessionRejection(CommandAcceptance a);

class CommandSessionCheck {
 public:
  /// Sessions remembered after they end: none of them is adopted again.
  static constexpr std::size_t kRetiredSessions = 4;

  /// A decoded command frame; `current_drives`: the frame in force has not
  /// yet timed out (the device's watchdog). Updates the session and the
  /// counters; never allocates.
  CommandAcceptance Accept(const CommandFrame& frame, bool current_drives);

  /// The session followed (0: none yet).
  uint32_t session() const { return session_; }
  uint32_t last_seq() const { return last_seq_; }
  uint32_t rx_lost() const { return rx_lost_; }
  uint32_t rx_session_rejected() const { return rx_session_rejected_; }
  uint32_t sessions_adopted() const { return sessions_adopted_; }

 private:
  bool Retired(uint32_t session) const;

  uint32_t session_ = 0;
  uint32_t last_seq_ = 0;
  std::array<uint32_t, kRetiredSessions> retired_{};  // 0: empty slot
  std::size_t next_retired_ = 0;
  uint32_t rx_lost_ = 0;
  uint32_t rx_session_rejected_ = 0;
  uint32_t sessions_adopted_ = 0;
};

}  // namespace stewart::hw
