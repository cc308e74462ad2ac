// The viewer's WebSocket messages as JSON text (docs/viewer.md has every
// field): the server's "scene", "frame", "reply" and "error" messages, and
// the parsing of what a page sends ("request", "playback").
//
// Numbers are rounded so a frame stays small and prints short: lengths,
// positions and sizes (m) to 1e-5, quaternion components to 1e-6, forces (N)
// to 1e-3, times (s) to 1e-6, milliseconds and microseconds to 1e-3,
// stiffness levels to 1e-4. A number that is not finite (NaN, +-inf) is
// written as null; the page treats a null as "not known" (docs/viewer.md).
// Text is UTF-8; invalid bytes in a string become U+FFFD.
//
// Compiled as C++17 and C++20 alike (the server's translation unit is C++17:
// see src/server.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include <nlohmann/json.hpp>

#include "tonus/host/viewer/frame.hpp"

namespace tonus::viewer {

// Sent in the scene message; bumped when a message changes incompatibly.
inline constexpr int kProtocolVersion = 1;

// Limits on what a page may send (larger or deeper: a bad message).
inline constexpr std::size_t kMaxClientMessageBytes = std::size_t{64} * 1024;
inline constexpr int kMaxClientJsonDepth = 32;
inline constexpr std::size_t kMaxRequestPathBytes = 512;
// Request ids are JSON integers a page can hold exactly (2^53 - 1).
inline constexpr std::uint64_t kMaxRequestId = (std::uint64_t{1} << 53U) - 1U;

// {"type":"scene", ...}
std::string to_json(const Scene& scene);
// {"type":"frame", ...}
std::string to_json(const Frame& frame);

// {"type":"reply","id":N,"status":S,"body":{...}}
std::string reply_json(std::uint64_t id, int status, const nlohmann::json& body);
// {"type":"error","error":"...","id":N}; "id" only when the bad message had a usable one.
std::string error_json(std::string_view error, std::optional<std::uint64_t> id = std::nullopt);

// ---- what a page sends ------------------------------------------------------

// {"type":"request","id":N,"method":"POST","path":"/gifts","body":{...}}:
// a control API call (docs/control.md), answered by a "reply" with the same id.
struct RequestMessage {
  std::uint64_t id = 0;
  std::string method;  // upper case, e.g. "GET", "POST", "PUT", "DELETE"
  std::string path;    // starts with '/'
  std::string body;    // the "body" member as JSON text; empty when absent or null
};

enum class PlaybackAction : std::uint8_t { play, pause, seek };
std::string_view to_string(PlaybackAction action);

// {"type":"playback","action":"play"|"pause"|"seek","position_s":x}
struct PlaybackMessage {
  PlaybackAction action = PlaybackAction::pause;
  double position_s = 0.0;  // seek only: finite, >= 0
};

// Why a message was refused, and its id when it had a usable one.
struct BadMessage {
  std::string error;
  std::optional<std::uint64_t> id;
};

using ClientMessage = std::variant<RequestMessage, PlaybackMessage, BadMessage>;

// Never throws: anything malformed (not JSON, too deep, too large, not an
// object, an unknown type, missing or mistyped fields, unknown fields) is a
// BadMessage naming what is wrong.
ClientMessage parse_client_message(std::string_view text);

}  // namespace tonus::viewer
