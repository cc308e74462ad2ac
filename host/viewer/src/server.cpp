// The viewer's server: websocketpp 0.8.2 (Debian's libwebsocketpp-dev) over
// standalone asio (libasio-dev), one thread.
//
// This translation unit is compiled as C++17 (host/viewer/CMakeLists.txt):
// websocketpp 0.8.2 names constructors and destructors with template-ids
// (`~server<config>()`, `basic<concurrency, names>(...)` in logger/basic.hpp),
// which C++20 made ill-formed (CWG 2237) and GCC 11+ rejects as an error
// with -std=c++20 (Debian 12's package carries no patch for it; upstream's fix
// is unreleased). Only this file and the tests' WebSocket client include
// websocketpp; the public headers it shares with the rest of tonus (C++20)
// compile as either, and hold no websocketpp type, so the library links into
// C++20 code as any other (same compiler, same libstdc++ ABI).
#include "tonus/host/viewer/server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <exception>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#ifndef ASIO_STANDALONE
#error "ASIO_STANDALONE must be defined (host/viewer/CMakeLists.txt): websocketpp uses asio, not boost::asio"
#endif
// asio's scheduler, inlined at -O2/-O3, trips GCC 12's -Wnull-dereference
// (a middle-end warning, so not silenced as a system header's would be).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>
#pragma GCC diagnostic pop

namespace tonus::viewer {

namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
using Clock = std::chrono::steady_clock;
using Message = std::shared_ptr<const std::string>;

constexpr std::size_t kMaxFileBytes = std::size_t{64} * 1024 * 1024;
constexpr long kOpenHandshakeTimeoutMs = 5000;  // a connection that never finishes its request is dropped

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// "host:port" for messages; IPv6 in brackets.
std::string host_port(const std::string& address, int port) {
  if (address.find(':') != std::string::npos) return "[" + address + "]:" + std::to_string(port);
  return address + ":" + std::to_string(port);
}

// The host name of a Host header ("127.0.0.1:8080", "[::1]:80", "localhost").
std::string host_name(std::string_view host) {
  if (!host.empty() && host.front() == '[') {
    const auto end = host.find(']');
    return std::string(host.substr(1, end == std::string_view::npos ? std::string_view::npos : end - 1));
  }
  return std::string(host.substr(0, host.rfind(':')));
}

std::string read_file(const std::filesystem::path& path, std::string& error, std::uintmax_t max_bytes = kMaxFileBytes) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) {
    error = "cannot read " + path.filename().string();
    return {};
  }
  if (size > max_bytes) {
    error = path.filename().string() + " is too large to serve";
    return {};
  }
  std::ifstream in(path, std::ios::binary);
  std::string body;
  body.resize(static_cast<std::size_t>(size));
  if (!in.read(body.data(), static_cast<std::streamsize>(body.size()))) {
    error = "cannot read " + path.filename().string();
    return {};
  }
  return body;
}

struct Connection {
  bool over_limit = false;  // more than max_buffered_bytes unwritten at the last frame
  Clock::time_point over_since;
};

// A short plain-text reply (errors, refusals).
void reply_text(const WsServer::connection_ptr& con, websocketpp::http::status_code::value status,
                const std::string& body) {
  con->set_status(status);
  con->replace_header("Content-Type", "text/plain; charset=utf-8");
  con->set_body(body + "\n");
}

// 200 with a file's bytes; a HEAD request gets only their length.
void reply_body(const WsServer::connection_ptr& con, const std::string& method, const std::string& content_type,
                const std::string& body) {
  con->set_status(websocketpp::http::status_code::ok);
  con->replace_header("Content-Type", content_type);
  if (method == "HEAD") {
    con->set_body("");
    con->replace_header("Content-Length", std::to_string(body.size()));
  } else {
    con->set_body(body);
  }
}

}  // namespace

bool is_loopback_address(std::string_view address) {
  const std::string a = lower(address);
  if (a == "localhost") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, a.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24U) == 127U;
  in6_addr v6{};
  if (inet_pton(AF_INET6, a.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
  }
  return false;
}

struct ViewerServer::Impl {
  ViewerConfig config;

  struct Counters {
    std::atomic<std::uint64_t> connections_open{0}, connections_total{0}, connections_refused{0},
        connections_closed_slow{0}, frames_published{0}, frames_coalesced{0}, frames_sent{0}, frames_dropped{0},
        messages_received{0}, bad_messages{0}, requests{0}, http_requests{0};
  } counters;

  std::mutex lifecycle;  // start / stop
  std::thread thread;
  std::atomic<bool> is_running{false};
  std::atomic<int> bound_port{0};
  std::string bound_url;  // under lifecycle

  // Shared between the callers' threads and the server's thread.
  std::mutex shared;
  asio::io_service* io = nullptr;  // while the thread may run handlers
  Message scene;                   // the latest scene
  Message pending_frame;           // published, not yet sent out
  bool frame_posted = false;       // a flush_frame() is queued
  bool scene_posted = false;       // a broadcast_scene() is queued
  std::shared_ptr<RequestHandler> request_handler;
  std::shared_ptr<PlaybackHandler> playback_handler;

  // The server's thread only.
  std::unique_ptr<WsServer> ws;
  std::unique_ptr<asio::steady_timer> stop_timer;
  std::map<Hdl, Connection, std::owner_less<Hdl>> connections;  // open WebSocket connections
  Message last_frame;                                           // sent to new connections
  bool stopping = false;

  explicit Impl(ViewerConfig c) : config(std::move(c)) {}

  // ---- lifecycle ----------------------------------------------------------------

  bool start(std::string& error) {
    const std::lock_guard<std::mutex> lock(lifecycle);
    if (thread.joinable()) {
      error = "the viewer is already running on " + bound_url;
      return false;
    }
    std::string address = config.bind_address;
    if (lower(address) == "localhost") address = "127.0.0.1";
    const std::string where = host_port(address, config.port);
    if (config.port < 0 || config.port > 65535) {
      error = "cannot listen on " + where + ": the port must be 0..65535";
      return false;
    }
    asio::error_code aec;
    const asio::ip::address ip = asio::ip::make_address(address, aec);
    if (aec) {
      error = "cannot listen on " + where + ": \"" + config.bind_address + "\" is not an IP address";
      return false;
    }
    if (!config.allow_remote && !is_loopback_address(address)) {
      error = "refusing to listen on " + where +
              ": not a loopback address; the viewer has no authentication, so serving it beyond this machine needs "
              "allow_remote";
      return false;
    }

    auto server = std::make_unique<WsServer>();
    try {
      configure(*server);
    } catch (const std::exception& e) {
      error = std::string("cannot set up the viewer's server: ") + e.what();
      return false;
    }
    websocketpp::lib::error_code ec;
    const asio::ip::tcp::endpoint endpoint(ip, static_cast<unsigned short>(config.port));
    server->listen(endpoint, ec);
    if (ec) {
      error = "cannot listen on " + where + ": " + bind_error(endpoint);
      return false;
    }
    server->start_accept(ec);
    if (ec) {
      error = "cannot listen on " + where + ": " + ec.message();
      return false;
    }
    const asio::ip::tcp::endpoint local = server->get_local_endpoint(aec);
    if (aec) {
      error = "cannot listen on " + where + ": " + aec.message();
      return false;
    }

    ws = std::move(server);
    stop_timer = std::make_unique<asio::steady_timer>(ws->get_io_service());
    stopping = false;
    connections.clear();
    last_frame.reset();
    bound_port = local.port();
    const std::string url_host = ip.is_unspecified() ? std::string(ip.is_v6() ? "::1" : "127.0.0.1") : address;
    bound_url = "http://" + host_port(url_host, local.port()) + "/";
    {
      const std::lock_guard<std::mutex> s(shared);
      io = &ws->get_io_service();
      pending_frame.reset();
      frame_posted = false;
      scene_posted = false;
    }
    is_running = true;
    thread = std::thread([this] { run(); });
    return true;
  }

  // Why binding `endpoint` fails (websocketpp reports only "pass_through").
  static std::string bind_error(const asio::ip::tcp::endpoint& endpoint) {
    asio::io_service probe_io;
    asio::ip::tcp::acceptor probe(probe_io);
    asio::error_code ec;
    probe.open(endpoint.protocol(), ec);
    if (!ec) probe.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) probe.bind(endpoint, ec);
    if (!ec) probe.listen(asio::socket_base::max_listen_connections, ec);
    if (ec == std::errc::address_in_use) return "the port is already in use (another tonusd?)";
    if (ec == std::errc::address_not_available) return "the address is not one of this machine's";
    if (ec == std::errc::permission_denied) return "permission denied";
    if (ec) return ec.message();
    return "the bind failed";
  }

  void run() {
    for (;;) {
      try {
        ws->run();
        return;
      } catch (const std::exception&) {
        // A handler threw past its own guard: keep serving unless stopping.
        if (stopping) return;
      }
    }
  }

  void stop() {
    const std::lock_guard<std::mutex> lock(lifecycle);
    if (!thread.joinable()) return;
    {
      const std::lock_guard<std::mutex> s(shared);
      asio::post(*io, [this] { begin_shutdown(); });
    }
    thread.join();
    {
      const std::lock_guard<std::mutex> s(shared);
      io = nullptr;
      pending_frame.reset();
    }
    connections.clear();
    last_frame.reset();
    stop_timer.reset();
    ws.reset();  // its io_service drops what was still queued
    counters.connections_open = 0;
    is_running = false;
    bound_port = 0;
    bound_url.clear();
  }

  // On the server's thread: stop accepting, close every connection (going
  // away), and stop the loop once they are gone or stop_timeout_ms passed.
  void begin_shutdown() {
    stopping = true;
    websocketpp::lib::error_code ec;
    if (ws->is_listening()) ws->stop_listening(ec);
    std::vector<Hdl> open;
    open.reserve(connections.size());
    for (const auto& entry : connections) open.push_back(entry.first);
    for (const Hdl& hdl : open) ws->close(hdl, websocketpp::close::status::going_away, "tonusd is stopping", ec);
    if (connections.empty()) {
      ws->stop();
      return;
    }
    stop_timer->expires_after(std::chrono::milliseconds(std::max(0, config.stop_timeout_ms)));
    stop_timer->async_wait([this](const asio::error_code& e) {
      if (!e) ws->stop();
    });
  }

  // ---- set-up -------------------------------------------------------------------

  void configure(WsServer& s) {
    s.clear_access_channels(websocketpp::log::alevel::all);
    s.clear_error_channels(websocketpp::log::elevel::all);
    s.init_asio();
    s.set_reuse_addr(true);  // SO_REUSEADDR only: a second server on the port still fails
    s.set_listen_backlog(64);
    s.set_max_message_size(kMaxClientMessageBytes);
    s.set_max_http_body_size(kMaxClientMessageBytes);
    s.set_open_handshake_timeout(kOpenHandshakeTimeoutMs);
    s.set_close_handshake_timeout(std::max(1, config.stop_timeout_ms / 2));
    s.set_socket_init_handler([](const Hdl&, asio::ip::tcp::socket& socket) {
      asio::error_code ec;
      socket.set_option(asio::ip::tcp::no_delay(true), ec);
    });
    s.set_validate_handler([this](const Hdl& hdl) { return validate(hdl); });
    s.set_open_handler([this](const Hdl& hdl) { on_open(hdl); });
    s.set_close_handler([this](const Hdl& hdl) { on_gone(hdl); });
    s.set_fail_handler([this](const Hdl& hdl) { on_gone(hdl); });
    s.set_message_handler([this](const Hdl& hdl, const WsServer::message_ptr& msg) { on_message(hdl, msg); });
    s.set_http_handler([this](const Hdl& hdl) { on_http(hdl); });
  }

  // While bound to loopback, a Host that names another machine is a DNS
  // rebinding attempt (a web page whose name now resolves to 127.0.0.1).
  [[nodiscard]] bool host_allowed(const WsServer::connection_ptr& con) const {
    if (config.allow_remote) return true;
    const std::string& host = con->get_request_header("Host");
    if (host.empty()) return true;  // HTTP/1.0 or a non-browser client
    const std::string name = host_name(host);
    return is_loopback_address(name);
  }

  // A browser always sends Origin with a WebSocket: it must be the page's own.
  static bool origin_allowed(const WsServer::connection_ptr& con) {
    const std::string origin = lower(con->get_request_header("Origin"));
    if (origin.empty()) return true;  // not a browser
    const std::string host = lower(con->get_request_header("Host"));
    return origin == "http://" + host || origin == "https://" + host;
  }

  // ---- WebSocket ------------------------------------------------------------------

  bool validate(const Hdl& hdl) {
    websocketpp::lib::error_code ec;
    const WsServer::connection_ptr con = ws->get_con_from_hdl(hdl, ec);
    if (ec) return false;
    const std::string path = con->get_request().get_uri();
    auto refuse = [&](websocketpp::http::status_code::value status, const std::string& why) {
      ++counters.connections_refused;
      reply_text(con, status, why);
      return false;
    };
    if (path.substr(0, path.find('?')) != "/ws") {
      return refuse(websocketpp::http::status_code::not_found, "the viewer's WebSocket is at /ws");
    }
    if (!host_allowed(con)) return refuse(websocketpp::http::status_code::forbidden, "Host is not a loopback name");
    if (!origin_allowed(con))
      return refuse(websocketpp::http::status_code::forbidden, "cross-origin WebSocket refused");
    if (stopping) return refuse(websocketpp::http::status_code::service_unavailable, "the viewer is stopping");
    if (connections.size() >= config.max_connections) {
      return refuse(websocketpp::http::status_code::service_unavailable,
                    "too many viewers (" + std::to_string(config.max_connections) + ")");
    }
    return true;
  }

  void on_open(const Hdl& hdl) {
    connections.emplace(hdl, Connection{});
    ++counters.connections_total;
    counters.connections_open = connections.size();
    Message scene_now;
    {
      const std::lock_guard<std::mutex> s(shared);
      scene_now = scene;
    }
    if (scene_now) send_control(hdl, *scene_now);
    if (scene_now && last_frame) send_control(hdl, *last_frame);
  }

  void on_gone(const Hdl& hdl) {
    connections.erase(hdl);
    counters.connections_open = connections.size();
    if (stopping && connections.empty()) {
      stop_timer->cancel();
      ws->stop();
    }
  }

  void close_slow(const Hdl& hdl, const std::string& why) {
    ++counters.connections_closed_slow;
    websocketpp::lib::error_code ec;
    ws->close(hdl, websocketpp::close::status::try_again_later, why, ec);
  }

  // Scene, replies and errors: always sent, unless the connection has piled
  // up twice its limit (it is not reading: closed).
  void send_control(const Hdl& hdl, const std::string& text) {
    websocketpp::lib::error_code ec;
    const WsServer::connection_ptr con = ws->get_con_from_hdl(hdl, ec);
    if (ec || con->get_state() != websocketpp::session::state::open) return;
    if (con->get_buffered_amount() > 2 * config.max_buffered_bytes) {
      close_slow(hdl, "not reading its messages");
      return;
    }
    con->send(text, websocketpp::frame::opcode::text);
  }

  void flush_frame() {
    Message frame;
    {
      const std::lock_guard<std::mutex> s(shared);
      frame = std::move(pending_frame);
      pending_frame.reset();
      frame_posted = false;
    }
    if (!frame || stopping) return;
    last_frame = frame;
    const Clock::time_point now = Clock::now();
    std::vector<Hdl> stalled;
    for (auto& [hdl, state] : connections) {
      websocketpp::lib::error_code ec;
      const WsServer::connection_ptr con = ws->get_con_from_hdl(hdl, ec);
      if (ec || con->get_state() != websocketpp::session::state::open) continue;
      if (con->get_buffered_amount() > config.max_buffered_bytes) {
        ++counters.frames_dropped;
        if (!state.over_limit) {
          state.over_limit = true;
          state.over_since = now;
        } else if (now - state.over_since > std::chrono::milliseconds(config.stall_timeout_ms)) {
          stalled.push_back(hdl);
        }
        continue;
      }
      state.over_limit = false;
      if (!con->send(*frame, websocketpp::frame::opcode::text)) ++counters.frames_sent;
    }
    for (const Hdl& hdl : stalled) close_slow(hdl, "too slow: frames were dropped for too long");
  }

  void broadcast_scene() {
    Message scene_now;
    {
      const std::lock_guard<std::mutex> s(shared);
      scene_now = scene;
      scene_posted = false;
    }
    if (!scene_now || stopping) return;
    std::vector<Hdl> open;
    open.reserve(connections.size());
    for (const auto& entry : connections) open.push_back(entry.first);
    for (const Hdl& hdl : open) send_control(hdl, *scene_now);
  }

  void on_message(const Hdl& hdl, const WsServer::message_ptr& msg) {
    ++counters.messages_received;
    if (msg->get_opcode() != websocketpp::frame::opcode::text) {
      ++counters.bad_messages;
      send_control(hdl, error_json("binary messages are not accepted: send JSON text"));
      return;
    }
    ClientMessage parsed = parse_client_message(msg->get_payload());
    if (auto* bad = std::get_if<BadMessage>(&parsed)) {
      ++counters.bad_messages;
      send_control(hdl, error_json(bad->error, bad->id));
      return;
    }
    if (auto* request = std::get_if<RequestMessage>(&parsed)) {
      ++counters.requests;
      send_control(hdl, answer(*request));
      return;
    }
    const auto& playback = std::get<PlaybackMessage>(parsed);
    std::shared_ptr<PlaybackHandler> handler;
    {
      const std::lock_guard<std::mutex> s(shared);
      handler = playback_handler;
    }
    std::string error;
    if (!handler || !*handler) {
      error = "playback: nothing is playing (no recording)";
    } else {
      try {
        error = (*handler)(playback);
      } catch (const std::exception& e) {
        error = std::string("playback: ") + e.what();
      }
    }
    if (!error.empty()) send_control(hdl, error_json(error));
  }

  std::string answer(const RequestMessage& request) {
    std::shared_ptr<RequestHandler> handler;
    {
      const std::lock_guard<std::mutex> s(shared);
      handler = request_handler;
    }
    if (!handler || !*handler) {
      return reply_json(request.id, 503, {{"error", "the control API is not available in this viewer"}});
    }
    try {
      const RequestReply reply = (*handler)(request.method, request.path, request.body);
      return reply_json(request.id, reply.status, reply.body);
    } catch (const std::exception& e) {
      return reply_json(request.id, 500, {{"error", std::string("the request failed: ") + e.what()}});
    }
  }

  // ---- plain HTTP: the page's files ------------------------------------------------

  void on_http(const Hdl& hdl) {
    ++counters.http_requests;
    websocketpp::lib::error_code ec;
    const WsServer::connection_ptr con = ws->get_con_from_hdl(hdl, ec);
    if (ec) return;
    con->replace_header("Cache-Control", "no-cache");
    con->replace_header("X-Content-Type-Options", "nosniff");
    auto text = [&](websocketpp::http::status_code::value status, const std::string& body) {
      reply_text(con, status, body);
    };
    if (!host_allowed(con)) {
      text(websocketpp::http::status_code::forbidden, "Host is not a loopback name");
      return;
    }
    const std::string& method = con->get_request().get_method();
    if (method != "GET" && method != "HEAD") {
      con->replace_header("Allow", "GET, HEAD");
      text(websocketpp::http::status_code::method_not_allowed, "only GET and HEAD are served here");
      return;
    }
    const std::string& target = con->get_request().get_uri();
    if (target.substr(0, target.find('?')) == "/ws") {
      text(websocketpp::http::status_code::upgrade_required, "this is the viewer's WebSocket: open / in a browser");
      return;
    }
    if (percent_decode(target.substr(0, target.find_first_of("?#"))) == std::string(kVrmUrl)) {
      serve_vrm(con, method);
      return;
    }
    const StaticTarget file = resolve_static(config.web_root, target);
    if (file.status != 200) {
      text(static_cast<websocketpp::http::status_code::value>(file.status), file.error);
      return;
    }
    std::string error;
    const std::string body = read_file(file.file, error);
    if (!error.empty()) {
      text(websocketpp::http::status_code::internal_server_error, error);
      return;
    }
    reply_body(con, method, std::string(mime_type(file.file)), body);
  }

  // The configured avatar, and only it: the request's path picks no file.
  void serve_vrm(const WsServer::connection_ptr& con, const std::string& method) const {
    auto text = [&](websocketpp::http::status_code::value status, const std::string& body) {
      reply_text(con, status, body);
    };
    if (config.vrm_file.empty()) {
      text(websocketpp::http::status_code::not_found, "no VRM avatar: start tonusd with --vrm FILE");
      return;
    }
    const std::filesystem::path path(config.vrm_file);
    const VrmFileInfo info = check_vrm_file(path);
    if (!info.error.empty()) {
      text(websocketpp::http::status_code::internal_server_error,
           "the VRM file " + path.filename().string() + " is not usable now: " + info.error);
      return;
    }
    std::string error;
    const std::string body = read_file(path, error, kMaxVrmBytes);
    if (!error.empty()) {
      text(websocketpp::http::status_code::internal_server_error, error);
      return;
    }
    reply_body(con, method, "model/gltf-binary", body);  // whatever the file is named
  }
};

ViewerServer::ViewerServer(ViewerConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}

ViewerServer::~ViewerServer() { stop(); }

bool ViewerServer::start(std::string& error) {
  error.clear();
  return impl_->start(error);
}

void ViewerServer::stop() { impl_->stop(); }

bool ViewerServer::running() const { return impl_->is_running; }

int ViewerServer::port() const { return impl_->bound_port; }

std::string ViewerServer::url() const {
  const std::lock_guard<std::mutex> lock(impl_->lifecycle);
  return impl_->bound_url;
}

void ViewerServer::set_request_handler(RequestHandler handler) {
  auto h = std::make_shared<RequestHandler>(std::move(handler));
  const std::lock_guard<std::mutex> s(impl_->shared);
  impl_->request_handler = std::move(h);
}

void ViewerServer::set_playback_handler(PlaybackHandler handler) {
  auto h = std::make_shared<PlaybackHandler>(std::move(handler));
  const std::lock_guard<std::mutex> s(impl_->shared);
  impl_->playback_handler = std::move(h);
}

void ViewerServer::set_scene(const Scene& scene) {
  Scene announced = scene;
  announced.vrm.reset();
  if (!impl_->config.vrm_file.empty()) {
    const std::filesystem::path path(impl_->config.vrm_file);
    const VrmFileInfo info = check_vrm_file(path);
    // Announced even when unusable now: the page then shows why, from the reply to its request.
    announced.vrm = SceneVrm{std::string(kVrmUrl), path.filename().string(), info.bytes};
  }
  auto message = std::make_shared<const std::string>(to_json(announced));
  Impl& d = *impl_;
  const std::lock_guard<std::mutex> s(d.shared);
  if (d.scene && *d.scene == *message) return;  // unchanged: nothing to re-send
  d.scene = std::move(message);
  if (d.io && !d.scene_posted) {
    d.scene_posted = true;
    asio::post(*d.io, [&d] { d.broadcast_scene(); });
  }
}

void ViewerServer::publish(const Frame& frame) {
  Impl& d = *impl_;
  if (!d.is_running) return;
  auto message = std::make_shared<const std::string>(to_json(frame));
  const std::lock_guard<std::mutex> s(d.shared);
  if (!d.io) return;
  ++d.counters.frames_published;
  if (d.pending_frame) ++d.counters.frames_coalesced;
  d.pending_frame = std::move(message);
  if (!d.frame_posted) {
    d.frame_posted = true;
    asio::post(*d.io, [&d] { d.flush_frame(); });
  }
}

ViewerStats ViewerServer::stats() const {
  const Impl::Counters& c = impl_->counters;
  ViewerStats s;
  s.connections_open = c.connections_open;
  s.connections_total = c.connections_total;
  s.connections_refused = c.connections_refused;
  s.connections_closed_slow = c.connections_closed_slow;
  s.frames_published = c.frames_published;
  s.frames_coalesced = c.frames_coalesced;
  s.frames_sent = c.frames_sent;
  s.frames_dropped = c.frames_dropped;
  s.messages_received = c.messages_received;
  s.bad_messages = c.bad_messages;
  s.requests = c.requests;
  s.http_requests = c.http_requests;
  return s;
}

}  // namespace tonus::viewer
