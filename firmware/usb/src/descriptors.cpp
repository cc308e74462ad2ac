#include "tonus/usb/descriptors.hpp"

namespace tonus::usb {

namespace {

// UTF-16LE string descriptor from ASCII.
std::size_t ascii(const char* s, std::span<std::uint8_t> out) {
  std::size_t n = 2;
  for (; *s != '\0' && n + 2 <= out.size(); ++s) {
    out[n++] = static_cast<std::uint8_t>(*s);
    out[n++] = 0;
  }
  out[0] = static_cast<std::uint8_t>(n);
  out[1] = desc::string;
  return n;
}

}  // namespace

std::size_t string_descriptor(std::uint8_t index, std::uint64_t serial, std::span<std::uint8_t> out) {
  if (out.size() < 4) return 0;
  switch (index) {
    case 0:
      out[0] = 4;
      out[1] = desc::string;
      out[2] = 0x09;  // English (United States)
      out[3] = 0x04;
      return 4;
    case 1: return ascii("tonus", out);
    case 2: return ascii("tonus EMG band", out);
    case 3: {
      char hex[17];
      for (int k = 0; k < 16; ++k) {
        const auto nibble = static_cast<unsigned>((serial >> (60U - 4U * static_cast<unsigned>(k))) & 0xFU);
        hex[k] = static_cast<char>(nibble < 10 ? '0' + nibble : 'A' + nibble - 10);
      }
      hex[16] = '\0';
      return ascii(hex, out);
    }
    default: return 0;
  }
}

}  // namespace tonus::usb
