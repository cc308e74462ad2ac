#include "tonus/host/control/server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/types.h>

#include <fmt/core.h>
#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "describe.hpp"
#include "tonus/host/control/router.hpp"

namespace tonus::control {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string json_error(int status, std::string_view message) {
  return dump_safe(Reply::error(status, message).body) + "\n";
}

// Messages for the errors cpp-httplib answers itself (before our routes).
std::string library_error_message(int status, std::size_t max_body_bytes) {
  switch (status) {
    case 400: return "malformed HTTP request";
    case 404: return "no such route";
    case 413: return fmt::format("request body larger than {} bytes", max_body_bytes);
    case 414: return "request URI too long";
    case 416: return "range not satisfiable";
    case 500: return "internal server error";
    default: return fmt::format("HTTP status {}", status);
  }
}

// Why bind() failed, from errno.
std::string bind_error(const std::string& address, int port, int err) {
  const std::string where = fmt::format("{}:{}", address, port);
  switch (err) {
    case EADDRINUSE: return fmt::format("cannot listen on {}: the port is already in use (another tonusd?)", where);
    case EADDRNOTAVAIL: return fmt::format("cannot listen on {}: the address is not one of this machine's", where);
    case EACCES: return fmt::format("cannot listen on {}: permission denied", where);
    case 0: return fmt::format("cannot listen on {}", where);
    default: return fmt::format("cannot listen on {}: {}", where, std::strerror(err));
  }
}

// SO_REUSEADDR only: cpp-httplib's default adds SO_REUSEPORT, which would let
// a second server (another tonusd) bind the same port and share the clients.
void socket_options(int sock) {
  int yes = 1;
  setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  const int flags = fcntl(sock, F_GETFD);
  if (flags >= 0) fcntl(sock, F_SETFD, flags | FD_CLOEXEC);
}

}  // namespace

bool is_loopback_address(const std::string& address) {
  if (lower(address) == "localhost") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, address.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24U) == 127U;
  in6_addr v6{};
  if (inet_pton(AF_INET6, address.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
  }
  return false;
}

struct ControlServer::Impl {
  Handler& handler;
  ServerLimits limits;
  std::mutex lifecycle;  // start / stop
  std::mutex calls;      // one Handler call at a time
  std::unique_ptr<httplib::Server> server;
  std::thread thread;
  std::atomic<bool> listen_returned{false};
  std::atomic<int> port{0};
  std::string address;

  Impl(Handler& h, ServerLimits l) : handler(h), limits(l) {}

  void serve(const httplib::Request& req, httplib::Response& res) {
    Routed routed;
    {
      const std::lock_guard<std::mutex> lock(calls);
      routed = route(handler, req.method, req.path, req.body);
    }
    std::string text;
    try {
      text = dump_safe(routed.reply.body) + "\n";
    } catch (const std::exception& e) {
      routed.reply.status = 500;
      text = json_error(500, std::string("reply not serialisable: ") + e.what());
    }
    res.status = routed.reply.status;
    if (!routed.allow.empty()) res.set_header("Allow", routed.allow);
    res.set_content(text, "application/json");
  }

  void configure(httplib::Server& s) {
    const int threads = std::max(1, limits.threads);
    s.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
    const auto timeout = static_cast<time_t>(std::max(1, limits.io_timeout_s));
    s.set_socket_options(socket_options);
    s.set_payload_max_length(limits.max_body_bytes);
    // One request per connection: a worker never idles on a kept-alive
    // connection while another client waits, and stop() is never held up by one.
    s.set_keep_alive_max_count(1);
    s.set_keep_alive_timeout(timeout);
    s.set_read_timeout(timeout, 0);
    s.set_write_timeout(timeout, 0);

    const httplib::Server::Handler all = [this](const httplib::Request& req, httplib::Response& res) {
      serve(req, res);
    };
    const std::string any = ".*";
    s.Get(any, all);  // GET and HEAD
    s.Post(any, all);
    s.Put(any, all);
    s.Delete(any, all);
    s.Patch(any, all);
    s.Options(any, all);

    // A request without Content-Length or Transfer-Encoding has no body
    // (RFC 9112 6.3), but cpp-httplib 0.11 waits for one on POST, PUT and
    // PATCH until the read times out: such requests are answered here,
    // before it tries to read (`curl -X POST .../calibration/rest`).
    const httplib::Server::HandlerWithResponse bodiless = [this](const httplib::Request& req, httplib::Response& res) {
      if (req.has_header("Content-Length") || req.has_header("Transfer-Encoding")) {
        return httplib::Server::HandlerResponse::Unhandled;
      }
      serve(req, res);
      return httplib::Server::HandlerResponse::Handled;
    };
    s.set_pre_routing_handler(bodiless);

    const std::size_t max_body = limits.max_body_bytes;
    const httplib::Server::HandlerWithResponse on_error = [max_body](const httplib::Request&, httplib::Response& res) {
      if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;  // ours, already JSON
      res.set_content(json_error(res.status, library_error_message(res.status, max_body)), "application/json");
      return httplib::Server::HandlerResponse::Handled;
    };
    s.set_error_handler(on_error);
    s.set_exception_handler([](const httplib::Request&, httplib::Response& res, const std::exception_ptr& ep) {
      std::string what = "unknown exception";
      try {
        if (ep) std::rethrow_exception(ep);
      } catch (const std::exception& e) {
        what = e.what();
      } catch (...) {
      }
      res.status = 500;
      res.set_content(json_error(500, "internal error: " + clip(what, 200)), "application/json");
    });
  }
};

ControlServer::ControlServer(Handler& handler, ServerLimits limits) : impl_(std::make_unique<Impl>(handler, limits)) {}

ControlServer::~ControlServer() { stop(); }

std::string ControlServer::start(const std::string& bind_address, int port, bool allow_remote) {
  const std::lock_guard<std::mutex> lock(impl_->lifecycle);
  Impl& m = *impl_;
  if (m.server) return fmt::format("the control server is already running on {}:{}", m.address, m.port.load());
  if (port < 0 || port > 65535) return fmt::format("cannot listen on port {}: not in 0..65535", port);
  if (bind_address.empty()) return "cannot listen: empty bind address";
  if (!allow_remote && !is_loopback_address(bind_address)) {
    return fmt::format(
        "refusing to bind the control API to {}: not a loopback address (127.0.0.1, ::1, localhost); the API has "
        "no authentication, so binding beyond this machine needs allow_remote",
        clip(bind_address, 100));
  }

  // Resolve first: cpp-httplib only says "failed".
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const int gai = getaddrinfo(bind_address.c_str(), std::to_string(port).c_str(), &hints, &found);
  if (gai != 0) {
    return fmt::format("cannot listen on {}: the address does not resolve ({})", clip(bind_address, 100),
                       gai_strerror(gai));
  }
  freeaddrinfo(found);

  try {
    auto server = std::make_unique<httplib::Server>();
    m.configure(*server);
    errno = 0;
    int bound = -1;
    if (port == 0) {
      bound = server->bind_to_any_port(bind_address);
    } else if (server->bind_to_port(bind_address, port)) {
      bound = port;
    }
    if (bound <= 0) return bind_error(bind_address, port, errno);

    m.listen_returned = false;
    httplib::Server* raw = server.get();
    m.thread = std::thread([&m, raw] {
      try {
        raw->listen_after_bind();
      } catch (...) {  // never let an exception end the process from this thread
      }
      m.listen_returned = true;
    });
    // Wait until the loop runs, so that a stop() right after start() is seen.
    while (!raw->is_running() && !m.listen_returned) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (!raw->is_running()) {
      m.thread.join();
      return fmt::format("cannot listen on {}:{}: the listen loop ended at once", bind_address, bound);
    }
    m.server = std::move(server);
    m.address = bind_address;
    m.port = bound;
  } catch (const std::exception& e) {
    if (m.thread.joinable()) m.thread.join();
    return fmt::format("cannot start the control server on {}:{}: {}", bind_address, port, e.what());
  }
  return {};
}

void ControlServer::stop() {
  const std::lock_guard<std::mutex> lock(impl_->lifecycle);
  Impl& m = *impl_;
  if (!m.server) return;
  m.server->stop();
  if (m.thread.joinable()) m.thread.join();
  m.server.reset();
  m.port = 0;
}

bool ControlServer::running() const { return impl_->port.load() != 0 && !impl_->listen_returned.load(); }

int ControlServer::port() const { return impl_->port.load(); }

const std::string& ControlServer::bind_address() const { return impl_->address; }

}  // namespace tonus::control
