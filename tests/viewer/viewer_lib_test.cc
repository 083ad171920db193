// The viewer's library without LCM or a browser: frames against the model's
// kinematics, the per-browser rate limit, the playback clock, the browser's
// messages (malformed ones included), the log index and the config section.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/config/viewer_config_loader.h"
#include "stewart/model/kinematics.h"
#include "stewart/viewer/client_message.h"
#include "stewart/viewer/frame_builder.h"
#include "stewart/viewer/frame_rate_limiter.h"
#include "stewart/viewer/latest_slot.h"
#include "stewart/viewer/lcm_log_index.h"
#include "stewart/viewer/playback_clock.h"

namespace stewart::viewer {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

TEST(FrameBuilder, LegsAreTheModelsInverseKinematicsAtTheEstimate) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const FrameBuilder builder(config.platform, config.safety, config.home_pose, {});
  ViewerSnapshot s;
  s.estimate.valid = true;
  s.estimate.utime_us = 15'000'000;
  s.estimate.q << 0.01, 0.1, 0.42, 0.01, -0.02, 0.03;
  const nlohmann::json frame = builder.Frame(s);
  const Vector6d lengths = InverseKinematics(config.platform, s.estimate.q);
  for (int i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(frame["legs"]["length_m"][i].get<double>(), lengths(i));
    EXPECT_DOUBLE_EQ(frame["estimate"]["q"][i].get<double>(), s.estimate.q(i));
    // The platform joint is the base joint plus the leg: its distance from
    // the base joint is the leg's length.
    Vector3d joint;
    for (int k = 0; k < 3; ++k)
      joint(k) = frame["legs"]["platform_joints_in_B_m"][i][k].get<double>();
    EXPECT_NEAR((joint - config.platform.base_joints_in_B_m.col(i)).norm(), lengths(i), 1e-12);
  }
  EXPECT_DOUBLE_EQ(frame["t_s"].get<double>(), 15.0);
  EXPECT_TRUE(frame["truth"].is_null()) << "no ground truth was given";
}

TEST(FrameBuilder, TheLastOperatorCommandIsNamedAndMarkedWhenItsMacFails) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const FrameBuilder builder(config.platform, config.safety, config.home_pose, {});
  ViewerSnapshot s;
  EXPECT_TRUE(builder.Frame(s)["operator_command"].is_null());
  s.last_operator_command = {true, 42, 7, 2, "bench check", false};
  nlohmann::json op = builder.Frame(s)["operator_command"];
  EXPECT_EQ(op["command"], "hold");
  EXPECT_EQ(op["operator_id"], "42");
  EXPECT_EQ(op["seq"], 7);
  EXPECT_EQ(op["note"], "bench check");
  EXPECT_FALSE(op["authentic"].get<bool>());
  s.last_operator_command.command = 99;  // not a command: named as such, no crash
  EXPECT_EQ(builder.Frame(s)["operator_command"]["command"], "unknown");
}

TEST(FrameBuilder, ALegNearTheEndOfItsStrokeIsFlagged) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const FrameBuilder builder(config.platform, config.safety, config.home_pose, {});
  ViewerSnapshot s;
  s.estimate.valid = true;
  s.estimate.q = config.home_pose;
  const nlohmann::json home = builder.Frame(s);
  for (int i = 0; i < 6; ++i) EXPECT_FALSE(home["legs"]["near_end"][i].get<bool>()) << "leg " << i;
  // Down towards the base until every leg is within 10 % of its shortest.
  s.estimate.q(2) = 0.0;
  for (double z = config.home_pose(2); z > 0.0; z -= 0.001) {
    s.estimate.q(2) = z;
    const Vector6d l = InverseKinematics(config.platform, s.estimate.q);
    const double share = (l.maxCoeff() - config.platform.leg_min_length_m) /
                         (config.platform.leg_max_length_m - config.platform.leg_min_length_m);
    if (share < FrameBuilder::kStrokeWarningShare) break;
  }
  const nlohmann::json low = builder.Frame(s);
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(low["legs"]["near_end"][i].get<bool>()) << "leg " << i;
}

TEST(FrameBuilder, HelloCarriesTheConfiguredLimits) {
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const FrameBuilder builder(config.platform, config.safety, config.home_pose, {});
  const nlohmann::json hello = builder.Hello({});
  ASSERT_EQ(hello["limits"]["position"].size(), config.safety.position_limits.size());
  EXPECT_DOUBLE_EQ(hello["limits"]["position"][1]["upper"].get<double>(),
                   *config.safety.position_limits[1].upper);
  EXPECT_EQ(hello["mode"], "live");
  EXPECT_FALSE(hello["operator"].get<bool>());
}

TEST(FrameRateLimiter, AtMostOneFramePerInterval) {
  FrameRateLimiter limiter(60.0);
  const Clock::time_point t0 = Clock::now();
  int sent = 0;
  // 1 s offered at 1 kHz: 60 frames, not 1000.
  for (int ms = 0; ms < 1000; ++ms) sent += limiter.TryTake(t0 + milliseconds(ms)) ? 1 : 0;
  EXPECT_GE(sent, 59);
  EXPECT_LE(sent, 60);
  EXPECT_THROW(FrameRateLimiter(0.0), InputError);
}

TEST(LatestSlot, ASlowReaderGetsTheNewestAndTheRestCountAsDropped) {
  LatestSlot<int> slot;
  EXPECT_FALSE(slot.Take().has_value());
  EXPECT_FALSE(slot.Offer(1));
  EXPECT_TRUE(slot.Offer(2));
  EXPECT_TRUE(slot.Offer(3));
  EXPECT_EQ(slot.Take(), 3) << "the newest frame, not the oldest";
  EXPECT_TRUE(slot.empty());
  EXPECT_EQ(slot.dropped(), 2);
  EXPECT_FALSE(slot.Offer(4)) << "a taken frame is not dropped";
  EXPECT_EQ(slot.dropped(), 2);
}

TEST(PlaybackClock, PlaysAtItsRateSeeksAndStopsAtTheEnd) {
  PlaybackClock clock(1'000'000, 21'000'000);
  const Clock::time_point t0 = Clock::now();
  EXPECT_EQ(clock.TimeAt(t0 + milliseconds(500)), 1'000'000) << "paused at start";
  clock.Play(t0);
  clock.SetRate(2.0, t0);
  EXPECT_EQ(clock.TimeAt(t0 + milliseconds(1000)), 3'000'000);
  clock.Seek(15'000'000, t0 + milliseconds(1000));
  EXPECT_EQ(clock.TimeAt(t0 + milliseconds(1000)), 15'000'000);
  EXPECT_EQ(clock.TimeAt(t0 + milliseconds(2000)), 17'000'000);
  EXPECT_EQ(clock.TimeAt(t0 + milliseconds(60000)), 21'000'000);
  EXPECT_FALSE(clock.playing()) << "pauses at the end";
  EXPECT_THROW(clock.SetRate(20.0, t0), InputError);
  EXPECT_THROW(clock.SetRate(0.05, t0), InputError);
  clock.Seek(-5, t0);
  EXPECT_EQ(clock.TimeAt(t0), 1'000'000) << "a seek is clamped to the log";
}

TEST(ClientMessage, ParsesTheControlsAndRefusesMalformedMessages) {
  EXPECT_EQ(ParseClientMessage(R"({"type":"seek","t_s":15})").t_s, 15.0);
  EXPECT_EQ(ParseClientMessage(R"({"type":"operator","command":"estop"})").operator_verb, "estop");
  EXPECT_EQ(ParseClientMessage(R"({"type":"rate","rate":0.5})").rate, 0.5);
  for (const char* bad :
       {"", "not json", "[1,2]", R"({"type":3})", R"({"type":"seek"})",
        R"({"type":"seek","t_s":"x"})", R"({"type":"operator","command":"heartbeat"})",
        R"({"type":"launch"})", "{\"type\":\"play\""}) {
    EXPECT_THROW(ParseClientMessage(bad), InputError) << bad;
  }
  EXPECT_THROW(ParseClientMessage(std::string(10000, ' ')), InputError) << "an oversized message";
}

// An LCM log event as lcm-logger writes it.
void WriteEvent(std::ofstream& out, int64_t event, const std::string& channel, int64_t utime) {
  auto be = [&](uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) out.put(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  be(0xEDA1DA01u, 4);
  be(static_cast<uint64_t>(event), 8);
  be(static_cast<uint64_t>(event) * 1000, 8);
  be(channel.size(), 4);
  be(24, 4);  // fingerprint, utime, seq
  out << channel;
  be(0x1234, 8);
  be(static_cast<uint64_t>(utime), 8);
  be(static_cast<uint64_t>(event), 8);
}

TEST(LcmLogIndex, FindsTheNewestMessageOfEachChannelAtAnyInstant) {
  const std::string path = ::testing::TempDir() + "viewer_index_test.lcm";
  {
    std::ofstream out(path, std::ios::binary);
    int64_t n = 0;
    for (int64_t t = 0; t < 20'000'000; t += 1000) {
      WriteEvent(out, n++, "STEWART_STATE_EST", t);
      if (t % 100'000 == 0) WriteEvent(out, n++, "STEWART_SUPERVISOR", t);
    }
    out << "\xED\xA1";  // a logger killed mid-event
  }
  const LcmLogIndex index(path);
  EXPECT_TRUE(index.truncated());
  EXPECT_EQ(index.EventsOf("STEWART_STATE_EST").size(), 20'000u);
  const LcmLogIndex::Event* e = index.LatestAtOrBefore("STEWART_STATE_EST", 15'000'500);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->utime_us, 15'000'000);
  const LcmLogIndex::Event* s = index.LatestAtOrBefore("STEWART_SUPERVISOR", 15'050'000);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->utime_us, 15'000'000);
  EXPECT_EQ(index.LatestAtOrBefore("STEWART_STATE_EST", -1), nullptr);
  EXPECT_TRUE(index.EventsOf("NO_SUCH_CHANNEL").empty());
  const std::vector<uint8_t> payload = index.Payload(*e);
  ASSERT_EQ(payload.size(), 24u);
  EXPECT_EQ(payload[8 + 7], static_cast<uint8_t>(15'000'000 & 0xff));
}

TEST(LcmLogIndex, AMissingOrForeignFileIsAClearError) {
  try {
    LcmLogIndex index("/nonexistent/log.lcm");
    FAIL() << "no error for a missing log";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/log.lcm"), std::string::npos) << e.what();
  }
  const std::string path = ::testing::TempDir() + "viewer_not_a_log.lcm";
  std::ofstream(path) << "this is a text file, not an LCM log\n";
  try {
    LcmLogIndex index(path);
    FAIL() << "no error for a text file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not an LCM log"), std::string::npos) << e.what();
  }
}

TEST(ViewerConfig, ShippedDefaultsAndOneErrorNamingABadKey) {
  const ViewerConfig shipped = LoadViewerConfig(DefaultConfigPath(), {});
  EXPECT_EQ(shipped.bind_address, "127.0.0.1") << "loopback by default";
  EXPECT_EQ(shipped.port, 8080);
  EXPECT_DOUBLE_EQ(shipped.max_frame_rate_hz, 60.0);
  const auto expect_error = [](const std::string& overlay_text, const std::string& key) {
    const std::string overlay = ::testing::TempDir() + "viewer_overlay.yaml";
    std::ofstream(overlay) << overlay_text;
    try {
      LoadViewerConfig(DefaultConfigPath(), {overlay});
      FAIL() << "accepted " << overlay_text;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  expect_error("viewer: {port: 70000}", "viewer.port");
  expect_error("viewer: {bind_address: localhost}", "viewer.bind_address");
  expect_error("viewer: {max_frame_rate_hz: -1}", "viewer.max_frame_rate_hz");
}

}  // namespace
}  // namespace stewart::viewer
