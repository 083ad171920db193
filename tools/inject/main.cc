// stewart_inject: puts hostile traffic on a running stack's bus, for the
// fault-injection tests and for soak runs by hand (docs/operations.md,
// "Faults on the bus").
//
//   stewart_inject --mode fragment-flood [--channel NAME]... --rate-hz 1000 --duration-s 2
//       first fragments, each declaring --declared-bytes (16 MiB), that never
//       complete
//   stewart_inject --mode garbage ...        short datagrams of random bytes
//   stewart_inject --mode truncate|wrong-fingerprint|duplicate|stale|future ...
//       each message heard on the channels, sent again changed: cut short,
//       the type's fingerprint flipped, as it was, its utime moved back or
//       forward by --shift-s (every message of the stack starts with int64
//       utime, right after the 8-byte fingerprint)
//   stewart_inject --mode nan|inf ...
//       each message of the loop heard on the channels (sensor_t, state_t,
//       setpoint_t, force_command_t, duty_command_t) sent again with every
//       measured or commanded value a quiet NaN (or +Inf), its fingerprint
//       and utime those of the original and its seq the original's + 1: a
//       time every check accepts, values that must be refused. The MAC of a
//       signed command is left as it was (it no longer verifies: with a key
//       the copy is refused as unauthentic before its values are read).
//       Other types (health, supervisor, operator, diagnostics) are not sent:
//       they carry no value a process acts on.
//   stewart_inject --mode clock-jump --shift-s S ...
//       the sensor clock jumps by S (negative: back) and runs on from there:
//       each sensor_t heard (default channel: the sensors) sent again with
//       utime and sample_utime moved by S and its own seq, numbered on from
//       the first heard, for the whole --duration-s. Unlike `future`/`stale`
//       (single copies, each 10 s off), a sustained second time base, as a
//       device whose clock jumped would send.
//
// --fragment-bytes N (every mode but fragment-flood) sends each message as a
// fragmented one, N bytes of it per fragment, where LCM sends these small
// messages whole: what a receiver does with a message must not depend on
// how it was cut into datagrams.
//
// Without --channel: every channel of the config. Sends to the config's URL
// (--lcm-url) with its TTL. Prints one line: what was sent. Exit 0, 2 on a
// bad flag.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "stewart/duty_command_t.hpp"
#include "stewart/force_command_t.hpp"
#include "stewart/node/lcm_receiver.h"
#include "stewart/node/node_main.h"
#include "stewart/node/raw_bus_sender.h"
#include "stewart/node/stop_signal.h"
#include "stewart/sensor_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"

namespace stewart {
namespace {

enum class Mode {
  kFragmentFlood,
  kGarbage,
  kTruncate,
  kWrongFingerprint,
  kDuplicate,
  kStale,
  kFuture,
  kNan,
  kInf,
  kClockJump
};

const std::map<std::string, Mode> kModes = {
    {"fragment-flood", Mode::kFragmentFlood},
    {"garbage", Mode::kGarbage},
    {"truncate", Mode::kTruncate},
    {"wrong-fingerprint", Mode::kWrongFingerprint},
    {"duplicate", Mode::kDuplicate},
    {"stale", Mode::kStale},
    {"future", Mode::kFuture},
    {"nan", Mode::kNan},
    {"inf", Mode::kInf},
    {"clock-jump", Mode::kClockJump},
};

struct Options {
  Mode mode = Mode::kGarbage;
  std::vector<std::string> channels;
  double rate_hz = 1000.0;
  double duration_s = 2.0;
  uint32_t declared_bytes = 16u << 20;
  double shift_s = 10.0;
  uint32_t seed = 1;
  size_t fragment_bytes = 0;  ///< 0: whole messages
};

constexpr int kFingerprintBytes = 8;
constexpr int kUtimeBytes = 8;

template <typename T, size_t N>
void Fill(T (&values)[N], T value) {
  for (T& v : values) v = value;
}

/// `m` decoded as `Msg` (false: another type or cut), poisoned and encoded
/// into `out` with seq + 1.
template <typename Msg, typename Poison>
bool Poisoned(const uint8_t* data, size_t size, Poison poison, std::vector<uint8_t>* out) {
  Msg m;
  if (m.decode(data, 0, static_cast<int>(size)) < 0) return false;
  m.seq += 1;
  poison(&m);
  out->resize(static_cast<size_t>(m.getEncodedSize()));
  return m.encode(out->data(), 0, static_cast<int>(out->size())) >= 0;
}

/// The loop's message `data` with every double `value` (quiet NaN or +Inf),
/// same fingerprint and utime, seq + 1; empty for any other type.
std::vector<uint8_t> PoisonValues(const uint8_t* data, size_t size, double value) {
  std::vector<uint8_t> out;
  if (Poisoned<sensor_t>(
          data, size,
          [value](sensor_t* m) {
            Fill(m->leg_length_m, value);
            Fill(m->gyro_radps, value);
            Fill(m->accel_mps2, value);
            Fill(m->orientation_rpy_rad, value);
          },
          &out) ||
      Poisoned<state_t>(
          data, size,
          [value](state_t* m) {
            Fill(m->q, value);
            Fill(m->qd, value);
            Fill(m->q_std, value);
            Fill(m->qd_std, value);
            Fill(m->disturbance, value);
            Fill(m->disturbance_std, value);
          },
          &out) ||
      Poisoned<setpoint_t>(
          data, size,
          [value](setpoint_t* m) {
            Fill(m->q_des, value);
            Fill(m->qd_des, value);
            Fill(m->qdd_des, value);
          },
          &out) ||
      Poisoned<force_command_t>(
          data, size, [value](force_command_t* m) { Fill(m->force_n, value); }, &out) ||
      Poisoned<duty_command_t>(
          data, size, [value](duty_command_t* m) { Fill(m->duty, value); }, &out)) {
    return out;
  }
  return {};
}

/// The sensor clock after the jump: each genuine sample moved by `shift_us`,
/// numbered on from the first one heard.
class JumpedClock {
 public:
  explicit JumpedClock(int64_t shift_us) : shift_us_(shift_us) {}
  /// `data` as the jumped device would send it; empty if not a sensor_t.
  std::vector<uint8_t> Next(const uint8_t* data, size_t size) {
    sensor_t m;
    if (m.decode(data, 0, static_cast<int>(size)) < 0) return {};
    if (next_seq_ < 0) next_seq_ = m.seq;
    m.utime += shift_us_;
    m.sample_utime += shift_us_;
    m.seq = next_seq_++;
    std::vector<uint8_t> out(static_cast<size_t>(m.getEncodedSize()));
    m.encode(out.data(), 0, static_cast<int>(out.size()));
    return out;
  }

 private:
  int64_t shift_us_;
  int64_t next_seq_ = -1;
};

/// A message heard on the bus, changed as `mode` asks; empty when the
/// message is too short to carry a fingerprint and a utime.
std::vector<uint8_t> Mutate(Mode mode, const uint8_t* data, size_t size, double shift_s,
                            std::mt19937* rng) {
  std::vector<uint8_t> payload(data, data + size);
  if (size < kFingerprintBytes + kUtimeBytes) return {};
  switch (mode) {
    case Mode::kTruncate: {
      std::uniform_int_distribution<size_t> cut(0, size - 1);
      payload.resize(cut(*rng));
      break;
    }
    case Mode::kWrongFingerprint:
      for (int i = 0; i < kFingerprintBytes; ++i) payload[static_cast<size_t>(i)] ^= 0x5a;
      break;
    case Mode::kStale:
    case Mode::kFuture: {
      int64_t utime = 0;
      for (int i = 0; i < kUtimeBytes; ++i) utime = (utime << 8) | payload[kFingerprintBytes + i];
      const auto shift_us = static_cast<int64_t>(shift_s * 1e6);
      utime += mode == Mode::kStale ? -shift_us : shift_us;
      for (int i = kUtimeBytes - 1; i >= 0; --i) {
        payload[static_cast<size_t>(kFingerprintBytes + i)] = static_cast<uint8_t>(utime);
        utime >>= 8;
      }
      break;
    }
    case Mode::kNan:
      return PoisonValues(data, size, std::numeric_limits<double>::quiet_NaN());
    case Mode::kInf:
      return PoisonValues(data, size, std::numeric_limits<double>::infinity());
    default:
      break;  // duplicate: as it was
  }
  return payload;
}

/// The messages this process sent last, by content: it hears its own
/// datagrams on the bus and must not change a copy again (a NaN copy's seq
/// + 1 would become + 2, a stale copy would move twice).
class SentRecently {
 public:
  void Add(const std::vector<uint8_t>& payload) {
    const uint64_t h = Hash(payload.data(), payload.size());
    if (ring_.size() == kKept) {
      set_.erase(set_.find(ring_[next_]));
      ring_[next_] = h;
    } else {
      ring_.push_back(h);
    }
    next_ = (next_ + 1) % kKept;
    set_.insert(h);
  }
  bool Contains(const uint8_t* data, size_t size) const { return set_.count(Hash(data, size)) > 0; }

 private:
  static constexpr size_t kKept = 4096;  // > a second of copies at the default rate
  static uint64_t Hash(const uint8_t* data, size_t size) {
    uint64_t h = 1469598103934665603ULL;  // FNV-1a
    for (size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ULL;
    return h;
  }
  std::vector<uint64_t> ring_;
  size_t next_ = 0;
  std::multiset<uint64_t> set_;
};

ExitCode Run(const StackConfig& config, const Options& options) {
  if (options.shift_s < 0.0 && options.mode != Mode::kClockJump) {
    spdlog::error("stewart_inject: --shift-s must not be negative for --mode stale|future");
    return ExitCode::kBadInput;
  }
  std::vector<std::string> channels = options.channels;
  if (channels.empty() && options.mode == Mode::kClockJump) {
    channels.push_back(config.lcm.channels.sensors);
  }
  if (channels.empty()) {
    for (const ChannelField& field : kChannelFields)
      channels.push_back(config.lcm.channels.*field.member);
  }
  RawBusSender bus(config.lcm.url);
  std::mt19937 rng(options.seed);
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration<double>(options.duration_s);
  const auto period = std::chrono::duration<double>(1.0 / options.rate_hz);
  int64_t sent = 0, failed = 0;
  uint32_t seqno = rng();
  auto send = [&](const std::vector<uint8_t>& datagram) {
    if (bus.Send(datagram)) {
      ++sent;
    } else {
      ++failed;
    }
  };
  if (options.fragment_bytes > 0 && options.mode == Mode::kFragmentFlood) {
    spdlog::error("stewart_inject: --fragment-bytes is for the modes that send whole messages");
    return ExitCode::kBadInput;
  }
  // One message, whole or in fragments; counted once, sent when the kernel
  // took every datagram of it.
  auto send_message = [&](const std::string& channel, const std::vector<uint8_t>& payload) {
    if (options.fragment_bytes == 0) {
      send(LcmShortDatagram(seqno++, channel, payload));
      return;
    }
    bool all = true;
    for (const auto& datagram :
         LcmFragmentedMessage(seqno++, channel, payload, options.fragment_bytes)) {
      all = bus.Send(datagram) && all;
    }
    ++(all ? sent : failed);
  };
  const bool from_bus = options.mode != Mode::kFragmentFlood && options.mode != Mode::kGarbage;
  if (!from_bus) {
    for (int64_t i = 0; !StopRequested(); ++i) {
      const auto at = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  period * static_cast<double>(i));
      if (at >= end) break;
      std::this_thread::sleep_until(at);
      const std::string& channel = channels[static_cast<size_t>(i) % channels.size()];
      if (options.mode == Mode::kFragmentFlood) {
        // The first of many fragments; the rest never come.
        const uint16_t fragments =
            static_cast<uint16_t>(std::min<uint32_t>(65535, options.declared_bytes / 1400 + 1));
        send(LcmFragmentDatagram(seqno++, options.declared_bytes, 0, 0, fragments, channel,
                                 std::vector<uint8_t>(1400, 0xab)));
      } else {
        std::uniform_int_distribution<int> length(0, 512);
        std::vector<uint8_t> payload(static_cast<size_t>(length(rng)));
        for (uint8_t& b : payload) b = static_cast<uint8_t>(rng());
        send_message(channel, payload);
      }
    }
  } else {
    // Changes what it hears, at most rate_hz messages a second.
    LcmReceiver receiver(config.lcm.url);
    std::map<std::string, bool> wanted;
    for (const std::string& c : channels) wanted[c] = true;
    auto next_allowed = start;
    JumpedClock jumped(static_cast<int64_t>(std::llround(options.shift_s * 1e6)));
    SentRecently own;
    receiver.SubscribeAll([&](const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
      if (!wanted.count(channel)) return;
      const auto* data = static_cast<const uint8_t*>(rbuf.data);
      if (own.Contains(data, rbuf.data_size)) return;
      const auto now = std::chrono::steady_clock::now();
      if (now < next_allowed) return;
      next_allowed = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
      const std::vector<uint8_t> payload =
          options.mode == Mode::kClockJump
              ? jumped.Next(data, rbuf.data_size)
              : Mutate(options.mode, data, rbuf.data_size, options.shift_s, &rng);
      if (payload.empty() && options.mode != Mode::kTruncate) return;
      own.Add(payload);
      send_message(channel, payload);
    });
    while (!StopRequested() && std::chrono::steady_clock::now() < end) receiver.HandleTimeout(10);
  }
  std::printf("stewart_inject: %lld %s sent (%lld refused by the kernel) on %zu channels\n",
              static_cast<long long>(sent),
              options.fragment_bytes > 0 ? "fragmented messages" : "datagrams",
              static_cast<long long>(failed), channels.size());
  std::fflush(stdout);
  return ExitCode::kOk;
}

}  // namespace
}  // namespace stewart

int main(int argc, char** argv) {
  using namespace stewart;
  auto options = std::make_shared<Options>();
  return NodeMain(
      argc, argv,
      {"inject", "puts hostile traffic on the bus (fault injection; docs/operations.md)"},
      [options](CLI::App& app) {
        app.add_option("--mode", options->mode, "what to send")
            ->transform(CLI::CheckedTransformer(kModes, CLI::ignore_case))
            ->required();
        app.add_option("--channel", options->channels,
                       "a channel to attack (repeatable; default: every channel of the config)");
        app.add_option("--rate-hz", options->rate_hz, "datagrams (or changed messages) per second")
            ->check(CLI::Range(1.0, 100000.0));
        app.add_option("--duration-s", options->duration_s, "how long")
            ->check(CLI::Range(0.0, 3600.0));
        app.add_option("--declared-bytes", options->declared_bytes,
                       "fragment-flood: the size each message declares")
            ->check(CLI::Range(1u, 1u << 30));
        app.add_option("--shift-s", options->shift_s,
                       "stale/future: how far utime moves; clock-jump: the jump (negative: back)")
            ->check(CLI::Range(-1e9, 1e9));
        app.add_option("--seed", options->seed, "random seed (garbage, truncate)");
        app.add_option("--fragment-bytes", options->fragment_bytes,
                       "send each message in fragments of this many bytes (0: whole)")
            ->check(CLI::Range(0, 65000));
      },
      nullptr, [options](const StackConfig& config, lcm::LCM*) { return Run(config, *options); });
}
