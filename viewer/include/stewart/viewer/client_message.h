#pragma once
// What a browser may send over the WebSocket: an operator command (only
// obeyed with --operator) or a playback control (only with --log). Anything
// else, or anything malformed, is an InputError whose message the viewer
// sends back to that browser; it never ends the viewer.
#include <string>
#include <string_view>

namespace stewart::viewer {

struct ClientMessage {
  enum class Kind { kOperator, kPlay, kPause, kRate, kSeek };
  Kind kind = Kind::kPause;
  /// kOperator: arm, hold, resume, estop or reset.
  std::string operator_verb;
  double rate = 1.0;  ///< kRate: playback speed (0.1 .. 10)
  double t_s = 0.0;   ///< kSeek: stack time to jump to (s)
};

/// Parses one text message, e.g. {"type":"seek","t_s":15}. Throws InputError.
ClientMessage ParseClientMessage(std::string_view text);

}  // namespace stewart::viewer
