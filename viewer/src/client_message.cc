#include "stewart/viewer/client_message.h"

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>

#include "stewart/common/check.h"

namespace stewart::viewer {
namespace {

// Bigger than any message the page sends: the parse of a huge one is refused
// before it costs memory.
constexpr std::size_t kMaxMessageBytes = 4096;

double Number(const nlohmann::json& msg, const char* key) {
  const auto it = msg.find(key);
  STEWART_CHECK_INPUT(it != msg.end() && it->is_number(), key, "a number is required");
  const double v = it->get<double>();
  STEWART_CHECK_INPUT(std::isfinite(v), key, "must be finite");
  return v;
}

}  // namespace

ClientMessage ParseClientMessage(std::string_view text) {
  STEWART_CHECK_INPUT(text.size() <= kMaxMessageBytes, "message",
                      "longer than " + std::to_string(kMaxMessageBytes) + " bytes");
  const nlohmann::json msg = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  STEWART_CHECK_INPUT(!msg.is_discarded(), "message", "not JSON");
  STEWART_CHECK_INPUT(msg.is_object(), "message", "not a JSON object");
  const auto type = msg.find("type");
  STEWART_CHECK_INPUT(type != msg.end() && type->is_string(), "type", "a string is required");
  const std::string kind = type->get<std::string>();
  ClientMessage out;
  if (kind == "operator") {
    static constexpr std::array<const char*, 5> kVerbs = {"arm", "hold", "resume", "estop",
                                                          "reset"};
    const auto command = msg.find("command");
    STEWART_CHECK_INPUT(command != msg.end() && command->is_string(), "command",
                        "a string is required");
    out.kind = ClientMessage::Kind::kOperator;
    out.operator_verb = command->get<std::string>();
    bool known = false;
    for (const char* verb : kVerbs) known = known || out.operator_verb == verb;
    STEWART_CHECK_INPUT(known, "command",
                        "'" + out.operator_verb + "' is not arm, hold, resume, estop or reset");
  } else if (kind == "play") {
    out.kind = ClientMessage::Kind::kPlay;
  } else if (kind == "pause") {
    out.kind = ClientMessage::Kind::kPause;
  } else if (kind == "rate") {
    out.kind = ClientMessage::Kind::kRate;
    out.rate = Number(msg, "rate");
  } else if (kind == "seek") {
    out.kind = ClientMessage::Kind::kSeek;
    out.t_s = Number(msg, "t_s");
  } else {
    throw InputError("type", "'" + kind + "' is not operator, play, pause, rate or seek");
  }
  return out;
}

}  // namespace stewart::viewer
