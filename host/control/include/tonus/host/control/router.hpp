// Routing without sockets: one HTTP request (method, path, body) to the
// Handler call it asks for, or to the error reply that refuses it. The
// server runs this for every request; tests can run it directly.
//
//   GET    /status                        -> Handler::status
//   POST   /gifts                         -> Handler::spawn_gift (JSON body)
//   DELETE /gifts                         -> Handler::clear_gifts
//   PUT    /stiffness                     -> Handler::set_stiffness_override (JSON body)
//   POST   /calibration/{rest|mvc|abort}  -> Handler::calibrate
//
// HEAD is GET. Invalid bodies: 400 {"error", "field"}; unknown path: 404;
// a known path with another method: 405 with the Allow header's value. A
// handler that throws, or answers a status outside 100..599: 500.
#pragma once

#include <string>
#include <string_view>

#include "tonus/host/control/api.hpp"

namespace tonus::control {

struct Routed {
  Reply reply;
  std::string allow;  // for a 405: the methods the path allows ("GET, HEAD")
};

Routed route(Handler& handler, std::string_view method, std::string_view path, std::string_view body);

}  // namespace tonus::control
