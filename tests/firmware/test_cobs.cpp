#include <doctest/doctest.h>

#include <vector>

#include "tonus/firmware/cobs.hpp"

using namespace tonus::fw;

TEST_CASE("COBS: known vectors and round trips") {
  // Vectors from Cheshire & Baker's paper / the Wikipedia table.
  const std::vector<std::uint8_t> in1{0x00};
  std::vector<std::uint8_t> out(300);
  REQUIRE(cobs::encode(in1, out) == 2);
  CHECK(out[0] == 0x01);
  CHECK(out[1] == 0x01);
  const std::vector<std::uint8_t> in2{0x11, 0x22, 0x00, 0x33};
  REQUIRE(cobs::encode(in2, out) == 5);
  CHECK(std::vector<std::uint8_t>(out.begin(), out.begin() + 5) ==
        std::vector<std::uint8_t>{0x03, 0x11, 0x22, 0x02, 0x33});
  for (std::size_t n : {0UL, 1UL, 7UL, 63UL, 253UL, 254UL, 255UL, 256UL}) {
    std::vector<std::uint8_t> msg(n);
    for (std::size_t k = 0; k < n; ++k) msg[k] = static_cast<std::uint8_t>((k * 37) % 5 == 0 ? 0 : k);
    std::vector<std::uint8_t> enc(cobs::max_encoded_size(n));
    const std::size_t e = cobs::encode(msg, enc);
    REQUIRE(e > 0);
    for (std::size_t k = 0; k < e; ++k) CHECK(enc[k] != 0);
    std::vector<std::uint8_t> dec(n + 1);
    CHECK(cobs::decode(std::span(enc).first(e), dec) == n);
    CHECK(std::vector<std::uint8_t>(dec.begin(), dec.begin() + static_cast<long>(n)) == msg);
  }
  const std::vector<std::uint8_t> bad{0x05, 0x11, 0x00};
  CHECK(cobs::decode(bad, out) == 0);
}
