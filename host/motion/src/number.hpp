// Locale-independent number parsing for BVH tokens.
#pragma once

#include <cstdint>
#include <string_view>

namespace tonus::motion {

enum class NumberStatus : std::uint8_t { ok, not_a_number, not_finite };

// A whole token as a decimal floating-point number: optional sign ('+'
// too), digits with an optional point (".5", "5."), optional exponent.
// Values too small for a double read as (signed) zero; values too large, and
// "inf"/"nan", are not_finite.
[[nodiscard]] NumberStatus parse_double(std::string_view token, double& out);

// A whole token as a non-negative decimal integer (digits only) no larger
// than `max`; false otherwise.
[[nodiscard]] bool parse_count(std::string_view token, std::uint64_t max, std::uint64_t& out);

}  // namespace tonus::motion
