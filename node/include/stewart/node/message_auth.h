#pragma once
// Message authentication on the bus (docs/operations.md, "Trust model").
//
// LCM multicast has no notion of a sender: any process that can reach the
// group can publish on any channel. With lcm.auth_key_file set, the messages
// that move the platform or change its supervision (CMD_SAFE, SUPERVISOR,
// OPERATOR) carry an HMAC-SHA256 tag in their `mac` field, computed over the
// message encoded with `mac` all zero, under a key shared by the stack's
// processes. A receiver with the key drops messages whose tag does not
// verify. Freshness (replays) is not the tag's job: sequence numbers,
// sessions and time windows on top of it handle that.
//
// Without a key the authenticator is disabled: Sign leaves the tag all zero
// and Verify accepts everything.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace stewart {

class MessageAuthenticator {
 public:
  static constexpr int kTagBytes = 32;
  static constexpr int kMinKeyBytes = 16;

  /// Disabled: no key.
  MessageAuthenticator() = default;
  /// Reads the key file: hex digits (whitespace ignored), at least 16 bytes.
  /// "" gives a disabled authenticator. Throws std::runtime_error naming the
  /// file for a missing, unreadable, malformed, short or group/world-readable
  /// key.
  static MessageAuthenticator FromKeyFile(const std::string& path);
  /// The raw key (tests); empty = disabled.
  explicit MessageAuthenticator(std::vector<uint8_t> key);

  bool enabled() const { return !key_.empty(); }

  /// Sets msg->mac to the tag of *msg (zero when disabled). Msg is an
  /// lcm-gen type with an `int8_t mac[32]` field.
  template <class Msg>
  void Sign(Msg* msg) {
    for (auto& b : msg->mac) b = 0;
    if (!enabled()) return;
    const std::array<uint8_t, kTagBytes> tag = TagOf(*msg);
    for (int i = 0; i < kTagBytes; ++i)
      msg->mac[i] = static_cast<int8_t>(tag[static_cast<size_t>(i)]);
  }

  /// True when disabled or when msg's tag verifies.
  template <class Msg>
  bool Verify(const Msg& msg) {
    if (!enabled()) return true;
    Msg zeroed = msg;
    for (auto& b : zeroed.mac) b = 0;
    const std::array<uint8_t, kTagBytes> tag = TagOf(zeroed);
    return TagsEqual(tag, reinterpret_cast<const uint8_t*>(msg.mac));
  }

  /// HMAC-SHA256 of bytes under the key.
  std::array<uint8_t, kTagBytes> Tag(const uint8_t* data, size_t size) const;

 private:
  template <class Msg>
  std::array<uint8_t, kTagBytes> TagOf(const Msg& zeroed) {
    const int size = zeroed.getEncodedSize();
    if (buffer_.size() < static_cast<size_t>(size)) buffer_.resize(static_cast<size_t>(size));
    zeroed.encode(buffer_.data(), 0, size);
    return Tag(buffer_.data(), static_cast<size_t>(size));
  }
  static bool TagsEqual(const std::array<uint8_t, kTagBytes>& a, const uint8_t* b);

  std::vector<uint8_t> key_;
  std::vector<uint8_t> buffer_;  // encode scratch, grown once
};

}  // namespace stewart
