// Shared by the control API tests: a Handler that records its calls, a
// server on 127.0.0.1 with a free port, and a raw TCP client.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tonus/host/control/api.hpp"
#include "tonus/host/control/client.hpp"
#include "tonus/host/control/server.hpp"

namespace tonus::control::testing {

class FakeHandler final : public Handler {
 public:
  Reply spawn_gift(const GiftRequest& request) override;
  Reply clear_gifts() override;
  Reply set_stiffness_override(const std::optional<Levels>& levels) override;
  Reply calibrate(CalibrationCommand command) override;
  Reply status() override;

  [[nodiscard]] std::vector<std::string> calls() const;
  [[nodiscard]] std::size_t call_count() const { return calls().size(); }

  // What the last calls carried.
  std::optional<GiftRequest> last_gift;
  std::optional<std::optional<Levels>> last_levels;
  std::optional<CalibrationCommand> last_calibration;

  // Behaviour knobs.
  std::chrono::milliseconds delay{0};  // each call sleeps this long
  bool throw_in_status = false;
  int status_code = 200;  // what status() answers
  std::atomic<int> max_concurrent{0};

 private:
  void enter(const char* name);
  void leave();
  mutable std::mutex mutex_;
  std::vector<std::string> calls_;
  std::atomic<int> concurrent_{0};
};

// A started server on 127.0.0.1, port chosen by the system.
struct RunningServer {
  FakeHandler handler;
  std::unique_ptr<ControlServer> server;
  explicit RunningServer(ServerLimits limits = {});
  [[nodiscard]] int port() const { return server->port(); }
  [[nodiscard]] ControlClient client(double timeout_s = 5.0) const {
    return ControlClient("127.0.0.1", port(), timeout_s);
  }
};

// Connects to 127.0.0.1:port; -1 on failure.
int connect_loopback(int port);

// Sends `bytes` on a new connection, optionally half-closes (cpp-httplib then
// drops the connection without a reply), and reads what comes back until the
// server closes or `timeout` passes.
std::string raw_exchange(int port, const std::string& bytes, bool half_close = false,
                         std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));

// The status code of a raw HTTP reply ("HTTP/1.1 405 ..."), 0 when none.
int raw_status(const std::string& reply);

// A port nothing listens on (bound and released).
int free_port();

}  // namespace tonus::control::testing
