#include "console.hpp"

#include <array>
#include <span>

#include "usart.hpp"

namespace tonus::f405::console {

void init() { usart::init(115200); }

void print(const char* text) {
  std::size_t n = 0;
  while (text[n] != '\0') ++n;
  usart::write(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text), n));
}

void print_u(std::uint64_t value) {
  std::array<std::uint8_t, 20> digits{};
  std::size_t n = 0;
  do {
    digits[digits.size() - 1 - n] = static_cast<std::uint8_t>('0' + value % 10U);
    value /= 10U;
    ++n;
  } while (value != 0);
  usart::write(std::span<const std::uint8_t>(digits).last(n));
}

void print_hex(std::uint64_t value) {
  std::array<std::uint8_t, 16> digits{};
  for (std::size_t k = 0; k < digits.size(); ++k) {
    const auto nibble = static_cast<std::uint8_t>((value >> (4U * (15U - k))) & 0xFU);
    digits[k] = static_cast<std::uint8_t>(nibble < 10 ? '0' + nibble : 'a' + nibble - 10);
  }
  usart::write(digits);
}

}  // namespace tonus::f405::console
