// The control API's HTTP server (cpp-httplib): listens on its own thread,
// answers on a pool of two threads, and calls the Handler (api.hpp) only with
// valid requests, one call at a time. See docs/control.md for the routes.
//
// Binding: loopback only (127.0.0.0/8, ::1, localhost) unless the caller
// passes allow_remote: the API has no authentication, so exposing it beyond
// this machine must be a deliberate choice.
//
// Limits: request bodies above max_body_bytes are refused (413); each
// connection serves one request and is closed; a client that sends nothing
// or stops halfway is dropped after io_timeout_s, which also bounds how long
// stop() waits for a connected client.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "tonus/host/control/api.hpp"

namespace tonus::control {

struct ServerLimits {
  int threads = 2;                                      // worker threads answering requests
  std::size_t max_body_bytes = std::size_t{64} * 1024;  // larger bodies: 413
  int io_timeout_s = 1;                                 // per read / write / idle wait, >= 1
};

// True for 127.0.0.0/8, ::1, ::ffff:127.x.x.x and "localhost".
bool is_loopback_address(const std::string& address);

class ControlServer {
 public:
  // `handler` must outlive the server (or at least its stop()).
  explicit ControlServer(Handler& handler, ServerLimits limits = {});
  ~ControlServer();  // stop()
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;
  ControlServer(ControlServer&&) = delete;
  ControlServer& operator=(ControlServer&&) = delete;

  // Bind and start answering (the listen loop on a thread of its own).
  // Returns an empty string once listening, else what went wrong (address
  // not loopback without allow_remote, address that does not resolve, port
  // in use, already running); never throws. Port 0 picks a free port.
  [[nodiscard]] std::string start(const std::string& bind_address = std::string(kDefaultBindAddress),
                                  int port = kDefaultPort, bool allow_remote = false);

  // Stop listening, finish the requests in flight, join the threads. Returns
  // within about io_timeout_s even with clients connected. Idempotent.
  void stop();

  [[nodiscard]] bool running() const;
  [[nodiscard]] int port() const;  // the bound port while running, else 0
  [[nodiscard]] const std::string& bind_address() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tonus::control
