#include "tonus/host/control/client.hpp"

#include <fmt/core.h>
#include <httplib.h>

#include <cmath>
#include <utility>

#include "describe.hpp"
#include "tonus/host/control/requests.hpp"

namespace tonus::control {

ControlClient::ControlClient(std::string host, int port, double timeout_s)
    : host_(std::move(host)), port_(port), timeout_s_(timeout_s) {}

ClientReply ControlClient::request(std::string_view method, const std::string& path, const std::string& body) const {
  ClientReply out;
  const std::string where = fmt::format("{}:{}", host_, port_);
  try {
    httplib::Client cli(host_, port_);
    const double t = std::isfinite(timeout_s_) && timeout_s_ > 0.0 ? timeout_s_ : 2.0;
    const auto sec = static_cast<time_t>(t);
    const auto usec = static_cast<time_t>((t - static_cast<double>(sec)) * 1e6);
    cli.set_connection_timeout(sec, usec);
    cli.set_read_timeout(sec, usec);
    cli.set_write_timeout(sec, usec);
    cli.set_keep_alive(false);

    httplib::Request req;
    req.method = std::string(method);
    req.path = path;
    req.body = body;
    if (!body.empty()) req.set_header("Content-Type", "application/json");
    const httplib::Result res = cli.send(req);
    if (!res) {
      const httplib::Error e = res.error();
      if (e == httplib::Error::Connection || e == httplib::Error::ConnectionTimeout) {
        out.error = fmt::format("cannot reach tonusd at {}: {}", where, httplib::to_string(e));
      } else {
        out.error = fmt::format("no reply from tonusd at {}: {}", where, httplib::to_string(e));
      }
      return out;
    }
    out.status = res->status;
    if (res->body.empty()) {
      if (req.method != "HEAD") out.error = fmt::format("empty reply from {} (HTTP {})", where, out.status);
      return out;
    }
    try {
      out.body = nlohmann::json::parse(res->body);
    } catch (const nlohmann::json::exception&) {
      out.error = fmt::format("the reply from {} (HTTP {}) is not JSON: {}", where, out.status, clip(res->body, 80));
    }
  } catch (const std::exception& e) {
    out.status = 0;
    out.body = nullptr;
    out.error = fmt::format("request to {} failed: {}", where, e.what());
  }
  return out;
}

ClientReply ControlClient::status() const { return request("GET", "/status"); }

ClientReply ControlClient::gift(const GiftRequest& r) const { return request("POST", "/gifts", to_json(r).dump()); }

ClientReply ControlClient::clear_gifts() const { return request("DELETE", "/gifts"); }

ClientReply ControlClient::set_stiffness(const std::optional<Levels>& levels) const {
  return request("PUT", "/stiffness", stiffness_body(levels).dump());
}

ClientReply ControlClient::calibrate(CalibrationCommand command) const {
  return request("POST", "/calibration/" + std::string(to_string(command)));
}

}  // namespace tonus::control
