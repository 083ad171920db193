#include "web_server.h"

#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <chrono>
#include <stdexcept>

#include "stewart/common/check.h"

namespace stewart::viewer {
namespace {

constexpr int kFinBit = 0x80;
constexpr int kOpcodeMask = 0x0f;

bool IsDirectory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

}  // namespace

WebServer::WebServer(WebServerOptions options, HelloFn hello, FrameFn frame, MessageFn on_message)
    : options_(std::move(options)),
      hello_(std::move(hello)),
      frame_(std::move(frame)),
      on_message_(std::move(on_message)) {
  if (!IsDirectory(options_.web_root)) {
    throw std::runtime_error("the page's folder " + options_.web_root + " does not exist");
  }
  if (!IsDirectory(options_.three_root)) {
    throw std::runtime_error("three.js is not at " + options_.three_root +
                             " (Debian package libjs-three; tools/setup.sh installs it)");
  }
  const ViewerConfig& c = options_.config;
  // civetweb keeps a worker thread per open WebSocket: the browsers, plus a
  // few for the page's files.
  const std::vector<std::string> civet_options = {"listening_ports",
                                                  c.bind_address + ":" + std::to_string(c.port),
                                                  "document_root",
                                                  options_.web_root,
                                                  "url_rewrite_patterns",
                                                  "/three/=" + options_.three_root + "/",
                                                  "enable_directory_listing",
                                                  "no",
                                                  "num_threads",
                                                  std::to_string(c.max_clients + 4),
                                                  "request_timeout_ms",
                                                  "5000",
                                                  "enable_websocket_ping_pong",
                                                  "yes"};
  try {
    server_ = std::make_unique<CivetServer>(civet_options);
  } catch (const CivetException& e) {
    throw std::runtime_error("cannot listen on " + c.bind_address + ":" + std::to_string(c.port) +
                             " (" + e.what() + "; is the port in use?)");
  }
  server_->addWebSocketHandler("/ws", this);
  publisher_ = std::thread([this] { PublishLoop(); });
}

WebServer::~WebServer() {
  stop_ = true;
  if (publisher_.joinable()) publisher_.join();
  // Closes every connection (their close handlers drop the senders) and
  // joins civetweb's threads.
  server_->close();
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  clients_.clear();
}

std::string WebServer::url() const {
  return "http://" + options_.config.bind_address + ":" + std::to_string(options_.config.port) +
         "/";
}

int WebServer::clients() const {
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  return static_cast<int>(clients_.size());
}

bool WebServer::handleConnection(CivetServer*, const mg_connection*) {
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  if (static_cast<int>(clients_.size()) >= options_.config.max_clients) {
    spdlog::warn("viewer: refused a browser: {} are connected (viewer.max_clients)",
                 clients_.size());
    return false;
  }
  return true;
}

void WebServer::handleReadyState(CivetServer*, mg_connection* conn) {
  auto sender = std::make_unique<ClientSender>(conn, options_.config.max_frame_rate_hz);
  sender->SendControl(hello_().dump());
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  clients_[conn] = std::move(sender);
  const mg_request_info* info = mg_get_request_info(conn);
  spdlog::info("viewer: browser connected from {} ({} connected)",
               info != nullptr ? info->remote_addr : "?", clients_.size());
}

void WebServer::ReplyError(mg_connection* conn, const std::string& message) {
  const std::lock_guard<std::mutex> lock(clients_mutex_);
  const auto it = clients_.find(conn);
  if (it == clients_.end()) return;
  it->second->SendControl(nlohmann::json{{"type", "error"}, {"message", message}}.dump());
}

bool WebServer::handleData(CivetServer*, mg_connection* conn, int bits, char* data,
                           size_t data_len) {
  const int opcode = bits & kOpcodeMask;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return false;
  if (opcode == MG_WEBSOCKET_OPCODE_PING || opcode == MG_WEBSOCKET_OPCODE_PONG) return true;
  if (opcode != MG_WEBSOCKET_OPCODE_TEXT || (bits & kFinBit) == 0) {
    ReplyError(conn, "only single-frame text messages are understood");
    return true;
  }
  try {
    const ClientMessage message = ParseClientMessage(std::string_view(data, data_len));
    on_message_(message);
  } catch (const InputError& e) {
    spdlog::warn("viewer: refused a browser message: {}", e.what());
    ReplyError(conn, e.what());
  } catch (const std::exception& e) {
    spdlog::error("viewer: a browser message failed: {}", e.what());
    ReplyError(conn, e.what());
  }
  return true;
}

void WebServer::handleClose(CivetServer*, const mg_connection* conn) {
  std::unique_ptr<ClientSender> sender;
  {
    const std::lock_guard<std::mutex> lock(clients_mutex_);
    const auto it = clients_.find(conn);
    if (it == clients_.end()) return;
    sender = std::move(it->second);
    clients_.erase(it);
  }
  spdlog::info("viewer: browser disconnected after {} frames ({} dropped for it)",
               sender->frames_sent(), sender->frames_dropped());
  // ~ClientSender joins its thread here, before civetweb frees conn.
}

void WebServer::PublishLoop() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / options_.config.max_frame_rate_hz));
  auto next = Clock::now();
  while (!stop_) {
    next += period;
    std::this_thread::sleep_until(next);
    if (Clock::now() > next + period) next = Clock::now();  // no catch-up burst after a stall
    bool anyone = false;
    {
      const std::lock_guard<std::mutex> lock(clients_mutex_);
      anyone = !clients_.empty();
    }
    if (!anyone) continue;  // nobody watching: build nothing
    nlohmann::json frame;
    try {
      frame = frame_();
    } catch (const std::exception& e) {
      spdlog::error("viewer: building a frame failed: {}", e.what());
      continue;
    }
    if (frame.is_null()) continue;
    // One serialisation shared by every browser.
    const auto text = std::make_shared<const std::string>(frame.dump());
    const std::lock_guard<std::mutex> lock(clients_mutex_);
    for (auto& [conn, sender] : clients_) sender->OfferFrame(text);
  }
}

}  // namespace stewart::viewer
