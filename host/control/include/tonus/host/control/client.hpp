// A client of the control API (cpp-httplib), one method per route. Never
// throws for network trouble: a daemon that cannot be reached is status 0
// and an error naming host:port.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "tonus/host/control/api.hpp"

namespace tonus::control {

// NOLINTNEXTLINE(bugprone-exception-escape): clang-tidy cannot prove nlohmann::json's moves noexcept
struct ClientReply {
  int status = 0;       // HTTP status; 0: no reply (see error)
  nlohmann::json body;  // the reply's JSON (null when none or not JSON)
  std::string error;    // empty when a JSON reply arrived, else what went wrong

  [[nodiscard]] bool reached() const { return status != 0; }
  [[nodiscard]] bool ok() const { return status >= 200 && status < 300 && error.empty(); }
};

class ControlClient {
 public:
  explicit ControlClient(std::string host = std::string(kDefaultBindAddress), int port = kDefaultPort,
                         double timeout_s = 2.0);

  ClientReply status() const;
  ClientReply gift(const GiftRequest& request) const;
  ClientReply clear_gifts() const;
  ClientReply set_stiffness(const std::optional<Levels>& levels) const;  // nullopt: release
  ClientReply calibrate(CalibrationCommand command) const;

  // Any request (method "GET", "POST", "PUT", "DELETE", "PATCH", ...) with a
  // raw body (sent as application/json when not empty).
  ClientReply request(std::string_view method, const std::string& path, const std::string& body = {}) const;

  [[nodiscard]] const std::string& host() const { return host_; }
  [[nodiscard]] int port() const { return port_; }

 private:
  std::string host_;
  int port_;
  double timeout_s_;
};

}  // namespace tonus::control
