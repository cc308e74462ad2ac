#include "tonus/host/control/router.hpp"

#include <fmt/core.h>

#include <exception>
#include <string>
#include <utility>

#include "describe.hpp"
#include "tonus/host/control/requests.hpp"

namespace tonus::control {

namespace {

constexpr std::string_view kRoutes =
    "GET /status, POST /gifts, DELETE /gifts, PUT /stiffness, POST /calibration/{rest|mvc|abort}";
constexpr std::string_view kCalibrationPrefix = "/calibration/";

Routed bad_request(const Invalid& why) {
  Reply r = Reply::error(400, why.message);
  r.body["field"] = why.field;
  return Routed{std::move(r), {}};
}

Routed not_allowed(std::string_view method, std::string_view path, std::string_view allow) {
  return Routed{Reply::error(405, fmt::format("method {} not allowed on {} (allowed: {})", clip(method, 20),
                                              clip(path, 100), allow)),
                std::string(allow)};
}

// The handler's reply, or a 500 when it throws or answers nonsense.
template <class Call>
Routed call_handler(std::string_view what, Call&& call) {
  Reply reply;
  try {
    reply = std::forward<Call>(call)();
  } catch (const std::exception& e) {
    return Routed{Reply::error(500, fmt::format("{} failed: {}", what, clip(e.what(), 200))), {}};
  } catch (...) {
    return Routed{Reply::error(500, fmt::format("{} failed", what)), {}};
  }
  if (reply.status < 200 || reply.status > 599) {
    return Routed{Reply::error(500, fmt::format("{} answered an invalid HTTP status {}", what, reply.status)), {}};
  }
  return Routed{std::move(reply), {}};
}

}  // namespace

Routed route(Handler& handler, std::string_view method, std::string_view path, std::string_view body) {
  if (method == "HEAD") method = "GET";

  if (path == "/status") {
    if (method != "GET") return not_allowed(method, path, "GET, HEAD");
    return call_handler("status", [&] { return handler.status(); });
  }

  if (path == "/gifts") {
    if (method == "POST") {
      auto parsed = parse_gift_request(body);
      if (const auto* bad = std::get_if<Invalid>(&parsed)) return bad_request(*bad);
      return call_handler("spawn_gift", [&] { return handler.spawn_gift(std::get<GiftRequest>(parsed)); });
    }
    if (method == "DELETE") return call_handler("clear_gifts", [&] { return handler.clear_gifts(); });
    return not_allowed(method, path, "POST, DELETE");
  }

  if (path == "/stiffness") {
    if (method != "PUT") return not_allowed(method, path, "PUT");
    auto parsed = parse_stiffness_request(body);
    if (const auto* bad = std::get_if<Invalid>(&parsed)) return bad_request(*bad);
    return call_handler("set_stiffness_override",
                        [&] { return handler.set_stiffness_override(std::get<std::optional<Levels>>(parsed)); });
  }

  if (path.starts_with(kCalibrationPrefix)) {
    const std::string_view name = path.substr(kCalibrationPrefix.size());
    const auto command = calibration_command_from_name(name);
    if (!command) {
      return Routed{
          Reply::error(404, fmt::format("no calibration command \"{}\" (expected rest, mvc or abort)", clip(name, 40))),
          {}};
    }
    if (method != "POST") return not_allowed(method, path, "POST");
    return call_handler("calibrate", [&] { return handler.calibrate(*command); });
  }

  return Routed{
      Reply::error(404, fmt::format("no route {} {} (routes: {})", clip(method, 20), clip(path, 100), kRoutes)), {}};
}

}  // namespace tonus::control
