// The live viewer's server (websocketpp over standalone asio): one port for
// the page (plain HTTP GET of static files, static_files.hpp) and its
// WebSocket at /ws, on one thread of its own. docs/viewer.md has the messages.
//
//   ViewerServer viewer(config);
//   viewer.set_request_handler(...);    // control API calls from the page
//   viewer.set_playback_handler(...);   // play / pause / seek from the page
//   if (std::string error; !viewer.start(error)) { ... }
//   viewer.set_scene(scene);            // sent to every connection, now and on connect
//   viewer.publish(frame);              // 30-60 times a second, from any thread
//   viewer.stop();                      // also done by the destructor
//
// publish() serialises the frame on the caller's thread and hands it to the
// server's thread through a one-frame slot: it never waits for a browser. A
// frame that arrives before the previous one went out replaces it (counted
// as coalesced). A connection with more than max_buffered_bytes not yet
// written to its socket skips frames (counted as dropped); one that stays
// over for stall_timeout_ms, or whose replies pile up past twice the limit,
// is closed. Nothing here queues without a bound.
//
// Handlers run on the server's thread, one at a time; they must not block
// long (every page waits while one runs).
//
// Safety: the page and its WebSocket have no authentication. Binding beyond
// loopback needs allow_remote. While bound to loopback the server refuses
// requests whose Host is not a loopback name (DNS rebinding), and always
// refuses a WebSocket whose Origin is not the page's own (another site open
// in the performer's browser cannot drive the avatar).
//
// This header compiles as C++17 and C++20 (the server's own translation
// unit is C++17: see src/server.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "tonus/host/viewer/frame.hpp"
#include "tonus/host/viewer/json.hpp"
#include "tonus/host/viewer/static_files.hpp"
#include "tonus/host/viewer/vrm_file.hpp"

namespace tonus::viewer {

inline constexpr int kDefaultPort = 39546;  // beside the control API's 39545
inline constexpr std::string_view kDefaultBindAddress = "127.0.0.1";

struct ViewerConfig {
  std::string bind_address = std::string(kDefaultBindAddress);  // an IP address or "localhost"
  int port = kDefaultPort;                                      // 0: the system picks one (port() tells)
  bool allow_remote = false;                                    // needed for any address outside 127.0.0.0/8 and ::1
  std::string web_root = default_web_root();
  // A VRM avatar served at kVrmUrl (vrm_file.hpp) and announced in the scene;
  // empty: none (kVrmUrl answers 404). Checked on every request: a file that
  // stopped being a usable glTF binary is refused with the reason.
  std::string vrm_file;
  std::size_t max_buffered_bytes = std::size_t{256} * 1024;  // per connection: frames beyond it are dropped
  std::size_t max_connections = 8;                           // WebSocket connections; more: 503
  int stall_timeout_ms = 10000;                              // a connection over max_buffered_bytes this long is closed
  int stop_timeout_ms = 1000;                                // stop() waits this long for closing handshakes, then cuts
};

// What a control API call answered (the daemon passes tonus::control::route's Reply).
struct RequestReply {
  int status = 200;
  nlohmann::json body = nlohmann::json::object();
};

// method ("GET", "POST", ...), path ("/gifts"), body (JSON text, empty when none).
using RequestHandler =
    std::function<RequestReply(std::string_view method, std::string_view path, std::string_view body)>;
// Returns an empty string when done, else why not (sent back as an "error" message).
using PlaybackHandler = std::function<std::string(const PlaybackMessage& command)>;

struct ViewerStats {
  std::uint64_t connections_open = 0;         // WebSocket connections now
  std::uint64_t connections_total = 0;        // ever opened
  std::uint64_t connections_refused = 0;      // over max_connections, bad path, Origin or Host
  std::uint64_t connections_closed_slow = 0;  // closed for stalling or piling up replies
  std::uint64_t frames_published = 0;         // publish() calls while running
  std::uint64_t frames_coalesced = 0;         // replaced in the slot before they went out
  std::uint64_t frames_sent = 0;              // frame messages queued to a connection (one per connection)
  std::uint64_t frames_dropped = 0;           // skipped for a connection over max_buffered_bytes
  std::uint64_t messages_received = 0;        // from pages
  std::uint64_t bad_messages = 0;             // malformed, answered with an "error" message
  std::uint64_t requests = 0;                 // "request" messages handed to the RequestHandler
  std::uint64_t http_requests = 0;            // plain HTTP requests (files)
};

class ViewerServer {
 public:
  explicit ViewerServer(ViewerConfig config = {});
  ~ViewerServer();  // stop()
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;
  ViewerServer(ViewerServer&&) = delete;
  ViewerServer& operator=(ViewerServer&&) = delete;

  // Binds and starts serving on a thread of its own. False with `error` set
  // (naming the address and port) when it cannot; never throws. A stopped
  // server can be started again.
  bool start(std::string& error);
  // Closes every connection (going away), stops listening and joins the
  // thread; within about stop_timeout_ms even with clients that do not
  // answer. Idempotent. Not from a handler (it runs on the thread it joins).
  void stop();

  [[nodiscard]] bool running() const;
  [[nodiscard]] int port() const;         // the bound port while running, else 0
  [[nodiscard]] std::string url() const;  // "http://127.0.0.1:PORT/" while running, else ""

  // Any time, from any thread. Without a request handler, requests are
  // answered 503; without a playback handler, playback messages get an error.
  void set_request_handler(RequestHandler handler);
  void set_playback_handler(PlaybackHandler handler);

  // Any time, from any thread (also before start()). A scene that differs
  // from the last one is sent to every open connection; each new connection
  // gets the latest scene, then the latest frame. Its `vrm` is set from
  // vrm_file here, whatever the caller put there.
  void set_scene(const Scene& scene);
  void publish(const Frame& frame);

  [[nodiscard]] ViewerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True for 127.0.0.0/8, ::1, ::ffff:127.x.x.x and "localhost".
bool is_loopback_address(std::string_view address);

}  // namespace tonus::viewer
