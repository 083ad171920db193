#include "stewart/common/check.h"

namespace stewart {

InputError::InputError(const std::string& key, const std::string& reason)
    : InputError(key, reason, key + ": " + reason) {}

InputError::InputError(const std::string& key, const std::string& reason,
                       const std::string& message)
    : std::invalid_argument(message), key_(key), reason_(reason) {}

namespace internal {

void FailCheck(const char* condition, const char* file, int line, const std::string& message) {
  throw std::logic_error(std::string(file) + ":" + std::to_string(line) + ": check '" + condition +
                         "' failed: " + message);
}

}  // namespace internal
}  // namespace stewart
