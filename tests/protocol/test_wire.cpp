#include <doctest/doctest.h>

#include <array>
#include <string_view>

#include "tonus/protocol/crc16.hpp"
#include "tonus/protocol/wire.hpp"

using namespace tonus::proto;

TEST_CASE("ByteWriter writes little-endian fields and stops at the end") {
  std::array<std::uint8_t, 16> buf{};
  ByteWriter w(buf);
  w.u8(0x01);
  w.u16(0x0302);
  w.u32(0x07060504);
  w.u64(0x0F0E0D0C0B0A0908ULL);
  CHECK(w.ok());
  CHECK(w.size() == 15);
  for (std::size_t i = 0; i < 15; ++i) CHECK(buf[i] == i + 1);
  w.u16(0xAAAA);  // needs 2 bytes, 1 left
  CHECK_FALSE(w.ok());
  CHECK(w.error() == Error::buffer_too_small);
  CHECK(buf[15] == 0);  // nothing partial written
  w.u8(0x55);           // sticky: still refused
  CHECK(w.size() == 15);
}

TEST_CASE("ByteReader reads little-endian fields and reports truncation") {
  const std::array<std::uint8_t, 7> buf{0x34, 0x12, 0x78, 0x56, 0x34, 0x12, 0xFF};
  ByteReader r(buf);
  CHECK(r.u16() == 0x1234);
  CHECK(r.u32() == 0x12345678);
  CHECK(r.ok());
  CHECK(r.u16() == 0);  // 1 byte left
  CHECK(r.error() == Error::truncated);
  CHECK(r.u8() == 0);  // sticky
}

TEST_CASE("CRC-16/CCITT-FALSE matches its catalogue check value") {
  constexpr std::string_view check = "123456789";
  std::array<std::uint8_t, 9> bytes{};
  for (std::size_t i = 0; i < check.size(); ++i) bytes[i] = static_cast<std::uint8_t>(check[i]);
  CHECK(crc16_ccitt(bytes) == 0x29B1);
  CHECK(crc16_ccitt({}) == 0xFFFF);
  static_assert(crc16_ccitt(std::array<std::uint8_t, 1>{0x00}) == 0xE1F0);
}
