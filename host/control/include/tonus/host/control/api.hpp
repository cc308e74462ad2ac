// The daemon's control API (docs/control.md): what a request asks for, once
// the library has parsed and validated it, and the Handler the daemon
// implements to carry it out. The library does not depend on the daemon: it
// owns the HTTP side (routing, parsing, validation, limits) and calls the
// Handler only with requests that are already valid.
//
// Threading: Handler methods run on the control server's own threads (a pool
// of two), never on the daemon's real-time thread. The server serializes the
// calls (one at a time, never two at once), but they may come from either of
// its threads. A handler must not block long: it should hand the request to
// the real-time thread (a lock-free queue, an atomic) and return; a slow
// handler holds up every other client.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "tonus/sim/human_bones.hpp"

namespace tonus::control {

inline constexpr int kDefaultPort = 39545;
inline constexpr std::string_view kDefaultBindAddress = "127.0.0.1";

// ---- gifts -----------------------------------------------------------------

enum class GiftKind : std::uint8_t { ball, cube };
std::string_view to_string(GiftKind k);
std::optional<GiftKind> gift_kind_from_name(std::string_view name);

// Accepted ranges (inclusive) of a gift's numbers; anything else is refused
// with HTTP 400 before the handler is called.
struct Range {
  double min, max;
  [[nodiscard]] bool contains(double v) const { return v >= min && v <= max; }
};
inline constexpr Range kMassKgRange{0.01, 20.0};
inline constexpr Range kSizeMRange{0.01, 1.0};
inline constexpr Range kSpeedMpsRange{0.0, 40.0};
inline constexpr Range kHeightMRange{0.0, 3.0};
inline constexpr Range kLifetimeSRange{0.0, 600.0};

// POST /gifts. Every optional field left empty means "the kind's default"
// (the daemon's business, e.g. tonus::avatar::ThrowBall / DropCube).
struct GiftRequest {
  GiftKind kind = GiftKind::ball;
  std::optional<sim::Bone> bone;  // target bone; empty: the kind's default
  std::optional<double> mass_kg;
  std::optional<double> size_m;      // a ball's diameter, a cube's edge
  std::optional<double> speed_mps;   // ball only: launch speed
  std::optional<double> height_m;    // cube only: drop height above the bone
  std::optional<double> lifetime_s;  // removed after this; 0: never
};

// ---- stiffness ---------------------------------------------------------------

// The band's four groups, in this order: right arm, left arm, trunk, legs
// (docs/protocol.md); each 0 (relaxed) .. 1 (full co-contraction).
inline constexpr std::size_t kLevelCount = 4;
using Levels = std::array<double, kLevelCount>;

// ---- calibration ---------------------------------------------------------------

enum class CalibrationCommand : std::uint8_t {
  rest,   // record the resting baseline
  mvc,    // record the maximum voluntary contraction
  abort,  // abort the running calibration phase
};
std::string_view to_string(CalibrationCommand c);
std::optional<CalibrationCommand> calibration_command_from_name(std::string_view name);

// ---- replies -------------------------------------------------------------------

// What the handler answers: an HTTP status and a JSON body (sent as is). For
// an error, use Reply::error(): body {"error": message}.
struct Reply {
  int status = 200;
  nlohmann::json body = nlohmann::json::object();

  static Reply ok(nlohmann::json body, int status = 200) { return Reply{status, std::move(body)}; }
  static Reply error(int status, std::string_view message);
};

// ---- the daemon's side ---------------------------------------------------------

class Handler {
 public:
  virtual ~Handler() = default;

  // POST /gifts: throw a ball or drop a cube (tonusd: 202 with the gift's id, queued for the next tick).
  virtual Reply spawn_gift(const GiftRequest& request) = 0;
  // DELETE /gifts: remove every gift.
  virtual Reply clear_gifts() = 0;
  // PUT /stiffness: override the band's levels; nullopt: back to the band.
  virtual Reply set_stiffness_override(const std::optional<Levels>& levels) = 0;
  // POST /calibration/{rest|mvc|abort}.
  virtual Reply calibrate(CalibrationCommand command) = 0;
  // GET /status: whatever the daemon reports.
  virtual Reply status() = 0;

 protected:
  Handler() = default;
  Handler(const Handler&) = default;
  Handler& operator=(const Handler&) = default;
  Handler(Handler&&) = default;
  Handler& operator=(Handler&&) = default;
};

}  // namespace tonus::control
