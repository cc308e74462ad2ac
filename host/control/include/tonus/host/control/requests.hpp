// The control API's request bodies: parsing and validation (the server's
// side) and building them (the client's side). Exposed for the tests and for
// other clients; the server calls them before any Handler method.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include <nlohmann/json.hpp>

#include "tonus/host/control/api.hpp"

namespace tonus::control {

// Why a request was refused: the field at fault ("body" for the body as a
// whole) and a message naming the field and the value, e.g.
// "mass_kg: 25 is out of range 0.01..20".
struct Invalid {
  std::string field;
  std::string message;
};

// POST /gifts body: {"kind": "ball"|"cube", "bone": "RightHand", "mass_kg": 1,
// "size_m": 0.1, "speed_mps": 8, "height_m": 0.3, "lifetime_s": 5}; only
// "kind" is required; null is the same as absent; unknown fields are refused,
// and so are speed_mps on a cube and height_m on a ball.
std::variant<GiftRequest, Invalid> parse_gift_request(std::string_view body);

// PUT /stiffness body: {"levels": [a, b, c, d]} (each 0..1) or
// {"levels": null} (release the override).
std::variant<std::optional<Levels>, Invalid> parse_stiffness_request(std::string_view body);

// The bodies a client sends (parse_* accepts them).
nlohmann::json to_json(const GiftRequest& request);
nlohmann::json stiffness_body(const std::optional<Levels>& levels);

}  // namespace tonus::control
