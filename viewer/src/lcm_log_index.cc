#include "stewart/viewer/lcm_log_index.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "stewart/common/check.h"

namespace stewart::viewer {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01u;
constexpr int kHeaderBytes = 4 + 8 + 8 + 4 + 4;  // sync, event number, timestamp, lengths
// lcm-gen's fingerprint, then the message's first field, int64 utime.
constexpr int kUtimeOffset = 8;
// No channel name is longer than LCM's limit; a bigger length is corruption.
constexpr int32_t kMaxChannelBytes = 256;

uint64_t BigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

const std::vector<LcmLogIndex::Event> kNoEvents;

}  // namespace

LcmLogIndex::LcmLogIndex(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw InputError("--log", "cannot open " + path + ": " + std::strerror(errno));
  // Indexing reads the file once, sequentially, through a buffer: a 40 s run
  // (~300k events) indexes in well under a second.
  std::vector<uint8_t> buffer(1 << 20);
  std::size_t have = 0, pos = 0;
  int64_t file_offset = 0;  // of buffer[0]
  bool eof = false;
  const auto ensure = [&](std::size_t bytes) {
    while (have - pos < bytes && !eof) {
      if (pos > 0) {
        std::memmove(buffer.data(), buffer.data() + pos, have - pos);
        file_offset += static_cast<int64_t>(pos);
        have -= pos;
        pos = 0;
      }
      if (buffer.size() < bytes) buffer.resize(bytes);
      const ssize_t n = ::read(fd_, buffer.data() + have, buffer.size() - have);
      if (n < 0) {
        if (errno == EINTR) continue;
        throw InputError("--log", "cannot read " + path + ": " + std::strerror(errno));
      }
      if (n == 0) eof = true;
      have += static_cast<std::size_t>(n);
    }
    return have - pos >= bytes;
  };
  while (ensure(kHeaderBytes)) {
    const uint8_t* h = buffer.data() + pos;
    if (BigEndian(h, 4) != kSyncWord) {
      if (total_events_ == 0) {
        ::close(fd_);
        throw InputError("--log", path + " is not an LCM log (no sync word at its start)");
      }
      truncated_ = true;  // garbage after complete events: keep what came before
      break;
    }
    const auto channel_bytes = static_cast<int32_t>(BigEndian(h + 20, 4));
    const auto payload_bytes = static_cast<int32_t>(BigEndian(h + 24, 4));
    if (channel_bytes <= 0 || channel_bytes > kMaxChannelBytes || payload_bytes < 0) {
      truncated_ = true;
      break;
    }
    pos += kHeaderBytes;
    if (!ensure(static_cast<std::size_t>(channel_bytes) +
                static_cast<std::size_t>(payload_bytes))) {
      truncated_ = true;
      break;
    }
    const std::string channel(reinterpret_cast<const char*>(buffer.data() + pos),
                              static_cast<std::size_t>(channel_bytes));
    pos += static_cast<std::size_t>(channel_bytes);
    const int64_t payload_offset = file_offset + static_cast<int64_t>(pos);
    if (payload_bytes >= kUtimeOffset + 8) {
      const auto utime = static_cast<int64_t>(BigEndian(buffer.data() + pos + kUtimeOffset, 8));
      auto it = std::find(channel_names_.begin(), channel_names_.end(), channel);
      if (it == channel_names_.end()) {
        channel_names_.push_back(channel);
        events_.emplace_back();
        it = channel_names_.end() - 1;
      }
      events_[static_cast<std::size_t>(it - channel_names_.begin())].push_back(
          {utime, payload_offset, payload_bytes});
    }
    pos += static_cast<std::size_t>(payload_bytes);
    ++total_events_;
  }
  if (have > pos) truncated_ = true;  // a partial header at the end
  if (total_events_ == 0) {
    ::close(fd_);
    throw InputError("--log", path + " holds no LCM event");
  }
  // Stack time within a channel only goes back when a publisher restarted;
  // ordering by it keeps the search exact either way.
  for (auto& events : events_) {
    std::stable_sort(events.begin(), events.end(),
                     [](const Event& a, const Event& b) { return a.utime_us < b.utime_us; });
  }
}

LcmLogIndex::~LcmLogIndex() {
  if (fd_ >= 0) ::close(fd_);
}

const std::vector<LcmLogIndex::Event>& LcmLogIndex::EventsOf(const std::string& channel) const {
  const auto it = std::find(channel_names_.begin(), channel_names_.end(), channel);
  if (it == channel_names_.end()) return kNoEvents;
  return events_[static_cast<std::size_t>(it - channel_names_.begin())];
}

const LcmLogIndex::Event* LcmLogIndex::LatestAtOrBefore(const std::string& channel,
                                                        int64_t utime_us) const {
  const std::vector<Event>& events = EventsOf(channel);
  const auto after = std::upper_bound(events.begin(), events.end(), utime_us,
                                      [](int64_t t, const Event& e) { return t < e.utime_us; });
  return after == events.begin() ? nullptr : &*(after - 1);
}

std::vector<uint8_t> LcmLogIndex::Payload(const Event& event) const {
  std::vector<uint8_t> data(static_cast<std::size_t>(event.payload_bytes));
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n =
        ::pread(fd_, data.data() + done, data.size() - done,
                static_cast<off_t>(event.payload_offset + static_cast<int64_t>(done)));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("cannot read " + path_ + " at its indexed offset");
    done += static_cast<std::size_t>(n);
  }
  return data;
}

}  // namespace stewart::viewer
