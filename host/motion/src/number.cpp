#include "number.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

namespace tonus::motion {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Whether an out-of-range decimal is too small (rather than too large): the
// decimal exponent of its first significant digit is negative.
bool underflows(std::string_view s) {
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  const std::size_t e = s.find_first_of("eE");
  const std::string_view mantissa = s.substr(0, e);
  long long exponent = 0;
  if (e != std::string_view::npos) {
    std::string_view digits = s.substr(e + 1);
    const bool negative = !digits.empty() && digits.front() == '-';
    if (!digits.empty() && (digits.front() == '-' || digits.front() == '+')) digits.remove_prefix(1);
    for (const char c : digits) {
      if (exponent < 1'000'000) exponent = exponent * 10 + (c - '0');  // saturates well past any double
    }
    if (negative) exponent = -exponent;
  }
  const std::size_t point = mantissa.find('.');
  const std::string_view integer = mantissa.substr(0, point);
  const std::size_t first = integer.find_first_not_of('0');
  if (first != std::string_view::npos) return static_cast<long long>(integer.size() - first) - 1 + exponent < 0;
  if (point == std::string_view::npos) return true;
  const std::string_view fraction = mantissa.substr(point + 1);
  const std::size_t nonzero = fraction.find_first_not_of('0');
  if (nonzero == std::string_view::npos) return true;
  return -static_cast<long long>(nonzero) - 1 + exponent < 0;
}

}  // namespace

NumberStatus parse_double(std::string_view token, double& out) {
  std::string_view s = token;
  // std::from_chars takes no '+'; some exporters write one.
  if (s.size() >= 2 && s.front() == '+' && (is_digit(s[1]) || s[1] == '.')) s.remove_prefix(1);
  if (s.empty()) return NumberStatus::not_a_number;
  double value = 0.0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, value, std::chars_format::general);
  if (ptr != end) return NumberStatus::not_a_number;
  if (ec == std::errc::result_out_of_range) {
    if (!underflows(s)) return NumberStatus::not_finite;
    out = s.front() == '-' ? -0.0 : 0.0;
    return NumberStatus::ok;
  }
  if (ec != std::errc{}) return NumberStatus::not_a_number;
  if (!std::isfinite(value)) return NumberStatus::not_finite;
  out = value;
  return NumberStatus::ok;
}

bool parse_count(std::string_view token, std::uint64_t max, std::uint64_t& out) {
  if (token.empty()) return false;
  std::uint64_t value = 0;
  for (const char c : token) {
    if (!is_digit(c)) return false;
    const auto digit = static_cast<std::uint64_t>(c - '0');
    if (digit > max || value > (max - digit) / 10) return false;
    value = value * 10 + digit;
  }
  out = value;
  return true;
}

}  // namespace tonus::motion
