#include "stewart/node/message_auth.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "stewart/force_command_t.hpp"
#include "stewart/operator_command_t.hpp"
#include "stewart/test_support/test_key.h"

namespace stewart {
namespace {

using ::stewart::test::TestKey;

force_command_t Command() {
  force_command_t c{};
  c.utime = 1234;
  c.seq = 5;
  c.sample_utime = 1234;
  c.session_id = 99;
  for (int i = 0; i < 6; ++i) c.force_n[i] = 1.5 * i;
  return c;
}

TEST(MessageAuth, SignedMessageVerifiesAndAnyChangeDoesNot) {
  MessageAuthenticator auth(TestKey(1));
  force_command_t c = Command();
  auth.Sign(&c);
  EXPECT_TRUE(auth.Verify(c));
  force_command_t forged = c;
  forged.force_n[2] += 1e-9;
  EXPECT_FALSE(auth.Verify(forged));
  forged = c;
  forged.seq += 1;
  EXPECT_FALSE(auth.Verify(forged));
  forged = c;
  forged.mac[0] ^= 1;
  EXPECT_FALSE(auth.Verify(forged));
  MessageAuthenticator other(TestKey(2));
  EXPECT_FALSE(other.Verify(c));
}

TEST(MessageAuth, StringFieldsAreCovered) {
  MessageAuthenticator auth(TestKey(3));
  operator_command_t o{};
  o.operator_id = 7;
  o.command = operator_command_t::COMMAND_ARM;
  o.note = "bench";
  auth.Sign(&o);
  EXPECT_TRUE(auth.Verify(o));
  o.note = "bench!";
  EXPECT_FALSE(auth.Verify(o));
}

TEST(MessageAuth, DisabledSignsZeroAndAcceptsAll) {
  MessageAuthenticator off;
  force_command_t c = Command();
  c.mac[3] = 42;
  off.Sign(&c);
  for (int8_t b : c.mac) EXPECT_EQ(b, 0);
  EXPECT_TRUE(off.Verify(c));
  // A receiver with a key rejects the unsigned message.
  MessageAuthenticator on(TestKey(1));
  EXPECT_FALSE(on.Verify(c));
}

TEST(MessageAuth, KnownAnswerRfc4231Case2) {
  // RFC 4231 test case 2: key "Jefe", data "what do ya want for nothing?".
  MessageAuthenticator auth(std::vector<uint8_t>{'J', 'e', 'f', 'e'});
  const std::string data = "what do ya want for nothing?";
  const auto tag = auth.Tag(reinterpret_cast<const uint8_t*>(data.data()), data.size());
  const uint8_t expected[8] = {0x5b, 0xdc, 0xc1, 0x46, 0xbf, 0x60, 0x75, 0x4e};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(tag[static_cast<size_t>(i)], expected[i]) << i;
}

std::string WriteKeyFile(const std::string& name, const std::string& text, mode_t mode) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  ::chmod(path.c_str(), mode);
  return path;
}

TEST(MessageAuth, KeyFileErrorsNameTheKey) {
  const std::string good =
      WriteKeyFile("auth_good.key", "00112233445566778899aabbccddeeff\n0011\n", 0600);
  EXPECT_TRUE(MessageAuthenticator::FromKeyFile(good).enabled());
  EXPECT_FALSE(MessageAuthenticator::FromKeyFile("").enabled());
  const auto expect_error = [](const std::string& path, const std::string& what) {
    try {
      MessageAuthenticator::FromKeyFile(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("lcm.auth_key_file"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error(::testing::TempDir() + "no_such.key", "no such file");
  expect_error(WriteKeyFile("auth_open.key", "00112233445566778899aabbccddeeff", 0644),
               "readable by group or others");
  expect_error(WriteKeyFile("auth_short.key", "0011223344", 0600), "shorter than");
  expect_error(WriteKeyFile("auth_text.key", "not a key at all, no", 0600), "not hex");
  expect_error(WriteKeyFile("auth_odd.key", "00112233445566778899aabbccddeeff0", 0600), "odd");
}

}  // namespace
}  // namespace stewart
