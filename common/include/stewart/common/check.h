#pragma once
// Two kinds of failed precondition, told apart because they are handled apart:
//
//   STEWART_CHECK(condition, message)
//       a programmer error (a caller broke a documented precondition). Always
//       evaluated, also in Release; throws std::logic_error naming the
//       condition, file and line. Cheap enough for a hot path: one branch.
//   STEWART_CHECK_INPUT(condition, key, reason)
//       bad input from a user (a config key, a command-line argument, a file):
//       throws InputError naming the key, so the user gets one clear line.
#include <stdexcept>
#include <string>

namespace stewart {

/// Bad user input. `key` names what was wrong ("safety.k_position",
/// "--variant", "truth.yaml: platform.mass_kg"); what() is "key: reason".
class InputError : public std::invalid_argument {
 public:
  InputError(const std::string& key, const std::string& reason);
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 protected:
  /// For subclasses that phrase the whole message themselves.
  InputError(const std::string& key, const std::string& reason, const std::string& message);

 private:
  std::string key_;
  std::string reason_;
};

namespace internal {
[[noreturn]] void FailCheck(const char* condition, const char* file, int line,
                            const std::string& message);
}  // namespace internal

}  // namespace stewart

#define STEWART_CHECK(condition, message)                                        \
  do {                                                                           \
    if (!(condition)) {                                                          \
      ::stewart::internal::FailCheck(#condition, __FILE__, __LINE__, (message)); \
    }                                                                            \
  } while (false)

#define STEWART_CHECK_INPUT(condition, key, reason) \
  do {                                              \
    if (!(condition)) {                             \
      throw ::stewart::InputError((key), (reason)); \
    }                                               \
  } while (false)
