#pragma once
// The viewer's HTTP side (civetweb): the page and three.js as static files,
// and one WebSocket (/ws) per browser over which frames go out and the
// page's commands come in. A thread of its own builds frames at the
// configured rate and hands each browser's sender the newest one.
#include <CivetServer.h>

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "client_sender.h"
#include "stewart/viewer/client_message.h"
#include "stewart/viewer/viewer_config.h"

namespace stewart::viewer {

struct WebServerOptions {
  ViewerConfig config;
  std::string web_root;    ///< the page (viewer/web)
  std::string three_root;  ///< three.js, served under /three/
};

class WebServer : public CivetWebSocketHandler {
 public:
  /// The next frame, or null when nothing changed since the previous one.
  using FrameFn = std::function<nlohmann::json()>;
  /// Sent to each browser once it connects.
  using HelloFn = std::function<nlohmann::json()>;
  /// A browser's command; throws InputError to refuse it (sent back to it).
  using MessageFn = std::function<void(const ClientMessage&)>;

  /// Starts listening; throws std::runtime_error naming the address when
  /// it cannot (port in use, bad address, missing web root).
  WebServer(WebServerOptions options, HelloFn hello, FrameFn frame, MessageFn on_message);
  ~WebServer() override;
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// The URL the page is at.
  std::string url() const;
  int clients() const;

  // CivetWebSocketHandler, called on civetweb's worker threads.
  bool handleConnection(CivetServer* server, const mg_connection* conn) override;
  void handleReadyState(CivetServer* server, mg_connection* conn) override;
  bool handleData(CivetServer* server, mg_connection* conn, int bits, char* data,
                  size_t data_len) override;
  void handleClose(CivetServer* server, const mg_connection* conn) override;

 private:
  void PublishLoop();
  void ReplyError(mg_connection* conn, const std::string& message);

  WebServerOptions options_;
  HelloFn hello_;
  FrameFn frame_;
  MessageFn on_message_;
  mutable std::mutex clients_mutex_;
  std::map<const mg_connection*, std::unique_ptr<ClientSender>> clients_;
  std::atomic<bool> stop_{false};
  std::unique_ptr<CivetServer> server_;
  std::thread publisher_;
};

}  // namespace stewart::viewer
