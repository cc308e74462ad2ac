// Shared by the viewer's tests: a WebSocket client (websocketpp, on a thread
// of its own) that records what it receives, raw loopback sockets for
// requests no well-behaved client would send, and a small scene and frame.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "tonus/host/viewer/frame.hpp"

namespace tonus::viewer::testing {

using namespace std::chrono_literals;
using Headers = std::vector<std::pair<std::string, std::string>>;

// A WebSocket client of ws://127.0.0.1:PORT/PATH. Compiled as C++17
// (websocketpp, as the server): no websocketpp type in this header.
class WsClient {
 public:
  explicit WsClient(int port, const std::string& path = "/ws", const Headers& headers = {});
  ~WsClient();
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;
  WsClient(WsClient&&) = delete;
  WsClient& operator=(WsClient&&) = delete;

  // True once open; false when the handshake failed or `timeout` passed.
  bool wait_open(std::chrono::milliseconds timeout = 3000ms);
  // The HTTP status of a refused handshake (0 while none).
  [[nodiscard]] int refused_status() const;

  void send(const std::string& text);
  void send_binary(const std::string& bytes);
  void close();

  [[nodiscard]] std::vector<nlohmann::json> messages() const;
  // The first message (from the start) that `match` accepts, waiting up to `timeout`.
  std::optional<nlohmann::json> wait_message(const std::function<bool(const nlohmann::json&)>& match,
                                             std::chrono::milliseconds timeout = 3000ms);
  // Waits until `done(messages)` holds.
  bool wait_for(const std::function<bool(const std::vector<nlohmann::json>&)>& done,
                std::chrono::milliseconds timeout = 3000ms);
  [[nodiscard]] bool closed() const;
  bool wait_closed(std::chrono::milliseconds timeout = 3000ms);
  [[nodiscard]] int close_code() const;  // the server's close code once closed

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Messages of a type ("scene", "frame", "reply", "error").
std::vector<nlohmann::json> of_type(const std::vector<nlohmann::json>& messages, const std::string& type);

// ---- raw sockets -----------------------------------------------------------------

// Connects to 127.0.0.1:port (blocking); -1 on failure. rcvbuf > 0 shrinks
// the receive buffer before connecting.
int connect_loopback(int port, int rcvbuf = 0);

struct HttpReply {
  int status = 0;
  std::string headers;  // lower-cased
  std::string body;
  [[nodiscard]] std::string header(const std::string& name) const;  // lower-case name, "" when absent
};

// Sends `request` as is and reads until the server closes (or `timeout`).
HttpReply http_raw(int port, const std::string& request, std::chrono::milliseconds timeout = 3000ms);
// GET (or another method) of a raw request target, with Host: 127.0.0.1:PORT.
HttpReply http_get(int port, const std::string& target, const std::string& method = "GET", const Headers& headers = {});

// A WebSocket handshake on a raw socket that then never reads: returns the
// socket (the caller closes it), -1 when the handshake failed.
int lazy_websocket(int port, int rcvbuf = 4096);

// Sends one masked WebSocket frame (FIN set) on a raw socket.
bool send_ws_frame(int fd, unsigned opcode, const std::string& payload);
// The server's (unmasked) frames in `bytes`: opcode and payload each; a
// truncated last frame is left out.
std::vector<std::pair<unsigned, std::string>> parse_ws_frames(const std::string& bytes);
// Whatever arrives on `fd` within `timeout` (until the peer closes).
std::string read_raw(int fd, std::chrono::milliseconds timeout);

// ---- data ------------------------------------------------------------------------

Scene small_scene();                    // three bones, two groups, one geom of each shape
Frame small_frame(std::uint64_t tick);  // poses for small_scene()

}  // namespace tonus::viewer::testing
