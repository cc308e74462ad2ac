// Internal: short, safe descriptions of JSON values and strings for error
// messages (never a deep dump of what a client sent).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace tonus::control {

// At most `n` bytes of `s`, with "..." when cut.
std::string clip(std::string_view s, std::size_t n);

// A scalar as JSON text (strings quoted, clipped); arrays and objects by kind.
std::string describe(const nlohmann::json& v);

// nlohmann's "[json.exception.parse_error.101] parse error at ..." without the tag.
std::string strip_json_exception(std::string_view what);

// JSON text that never throws (invalid UTF-8 replaced).
std::string dump_safe(const nlohmann::json& v, int indent = -1);

}  // namespace tonus::control
