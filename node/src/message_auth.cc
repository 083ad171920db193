#include "stewart/node/message_auth.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/stat.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace stewart {
namespace {

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

MessageAuthenticator::MessageAuthenticator(std::vector<uint8_t> key) : key_(std::move(key)) {}

MessageAuthenticator MessageAuthenticator::FromKeyFile(const std::string& path) {
  if (path.empty()) return MessageAuthenticator();
  const std::string what = "lcm.auth_key_file '" + path + "'";
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error(what + ": no such file");
  // A key others can read authenticates nothing.
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0) {
    throw std::runtime_error(what + ": readable by group or others (chmod 600 it)");
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error(what + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  std::vector<uint8_t> key;
  int high = -1;
  for (const char c : text.str()) {
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    const int v = HexValue(c);
    if (v < 0)
      throw std::runtime_error(what + ": not hex digits (expected e.g. `openssl rand -hex 32`)");
    if (high < 0) {
      high = v;
    } else {
      key.push_back(static_cast<uint8_t>(high * 16 + v));
      high = -1;
    }
  }
  if (high >= 0) throw std::runtime_error(what + ": odd number of hex digits");
  if (key.size() < static_cast<size_t>(kMinKeyBytes)) {
    throw std::runtime_error(what + ": key shorter than " + std::to_string(kMinKeyBytes) +
                             " bytes");
  }
  return MessageAuthenticator(std::move(key));
}

std::array<uint8_t, MessageAuthenticator::kTagBytes> MessageAuthenticator::Tag(const uint8_t* data,
                                                                               size_t size) const {
  std::array<uint8_t, kTagBytes> tag{};
  unsigned int length = 0;
  if (HMAC(EVP_sha256(), key_.data(), static_cast<int>(key_.size()), data, size, tag.data(),
           &length) == nullptr ||
      length != kTagBytes) {
    throw std::runtime_error("HMAC-SHA256 failed");
  }
  return tag;
}

bool MessageAuthenticator::TagsEqual(const std::array<uint8_t, kTagBytes>& a, const uint8_t* b) {
  return CRYPTO_memcmp(a.data(), b, kTagBytes) == 0;  // constant time
}

}  // namespace stewart
